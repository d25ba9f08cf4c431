//! Render lines in every variant; the camera and output of some are settled in `resolve`.

use super::{Anchor, At, PResult, Parser};
use crate::limits::{self, DEFAULT_IMAGE_SIZE};

use crate::sdf::ast::{NameRef, RenderDef, StatementKind};
use crate::sdf::lexer::{self, looks_numeric, Line};
use std::ops::Range;

const FORM_RENDER: &str = "render <camera> <file> <width> <height> [<samples>]";

/// How a render-like line named its camera.
pub(super) enum RenderCamera {
    Named,
    /// A lone name that is either a camera (no file given) or a file (no camera given);
    /// decided once every camera of the file is known.
    Ambiguous(String),
    Missing,
}

/// A render statement whose camera or output is settled after the whole file is read.
pub(super) struct PendingRender {
    pub(super) index: usize,
    pub(super) anchor: Anchor,
    pub(super) camera: RenderCamera,
    pub(super) output_given: bool,
    /// Where the output name is written (the whole line if it is not).
    pub(super) output_anchor: Anchor,
    /// Descriptions of the variants read on this line, for one warning.
    pub(super) notes: Vec<String>,
    /// Whether the line gives the image size.
    pub(super) size_given: bool,
}

/// The names of a render line, read.
struct RenderNames {
    camera: RenderCamera,
    /// The token naming the camera, or that may (`RenderCamera::Ambiguous`).
    camera_at: Option<usize>,
    output: Option<String>,
    /// Where the output name is written.
    output_at: At,
    /// The words after the image size.
    tail: Range<usize>,
}

impl Parser<'_> {
    /// A render-like line with its arguments from `from`. `camera_expected` is false for the
    /// variants that never name a camera (`renderer <file>`, `define render <file> w h`).
    pub(super) fn render(
        &mut self,
        line: &Line,
        from: usize,
        camera_expected: bool,
        variant: Option<&str>,
    ) {
        self.render_lines += 1;
        let reported = self.diagnostics.len();
        let statements = self.statements.len();
        self.render_inner(line, from, camera_expected, variant);
        if self.statements.len() == statements {
            // Rejected: whether that stops the file depends on its other render lines.
            let problems = self.diagnostics.split_off(reported);
            self.render_errors.extend(problems);
        }
    }

    fn render_inner(
        &mut self,
        line: &Line,
        from: usize,
        camera_expected: bool,
        variant: Option<&str>,
    ) {
        let mut notes: Vec<String> = variant.map(str::to_string).into_iter().collect();
        let names_end = names_end(line, from);
        let nums_end = Self::number_run_end(line, names_end);
        let Ok(RenderNames {
            camera,
            camera_at,
            output,
            output_at,
            tail,
        }) = self.render_names(line, from..names_end, nums_end, camera_expected, &mut notes)
        else {
            return;
        };
        let Ok(nums) = self.numbers(line, names_end, nums_end) else {
            return;
        };
        let Ok((width, height)) = self.image_size(line, names_end, &nums, &mut notes) else {
            return;
        };
        let Ok(samples) = self.samples(line, names_end, nums_end, &nums) else {
            return;
        };
        if !tail.is_empty() {
            self.warn(
                line,
                At::Span(tail.start, tail.end - 1),
                "words after the image size ignored",
                Some(format!("canonical form: `{FORM_RENDER}`")),
            );
        }
        let camera_ref = match camera_at {
            Some(i) if matches!(camera, RenderCamera::Named) => self.name_ref(line, i),
            // Settled in `resolve_renders`.
            Some(i) => NameRef {
                name: String::new(),
                loc: self.loc(line, At::Tok(i)),
            },
            None => NameRef {
                name: String::new(),
                loc: self.loc(line, At::Tok(0)),
            },
        };
        let output_given = output.is_some();
        let def = RenderDef {
            camera: camera_ref,
            output: output.unwrap_or_default(),
            width,
            height,
            samples,
        };
        let anchor = self.anchor(line, At::Tok(0));
        let output_anchor = self.anchor(line, output_at);
        self.pending.push(PendingRender {
            index: self.statements.len(),
            anchor,
            camera,
            output_given,
            output_anchor,
            notes,
            size_given: !nums.is_empty(),
        });
        self.emit(line, StatementKind::Render(def));
    }

    /// How the names of a render line (tokens `names`, before its numbers, which end at
    /// `nums_end`) divide into its camera and its file.
    fn render_names(
        &mut self,
        line: &Line,
        names: Range<usize>,
        nums_end: usize,
        camera_expected: bool,
        notes: &mut Vec<String>,
    ) -> PResult<RenderNames> {
        let toks = &line.tokens;
        let (from, names_end) = (names.start, names.end);
        let mut tail = nums_end..toks.len();
        let mut camera = RenderCamera::Missing;
        let mut camera_at = None;
        let mut output: Option<String> = None;
        let mut output_at = At::Tok(0);
        let file_pieces = match (camera_expected, names.len()) {
            (_, 0) => None,
            (true, 1) => {
                if tail.len() == 1 && nums_end - names_end >= 2 {
                    // `render cam 800 600 out.ppm`
                    notes.push("image size written before the file name".to_string());
                    camera = RenderCamera::Named;
                    camera_at = Some(from);
                    let pieces = tail.clone();
                    tail = toks.len()..toks.len();
                    Some(pieces)
                } else {
                    camera = RenderCamera::Ambiguous(toks[from].text.to_string());
                    camera_at = Some(from);
                    output_at = At::Tok(from);
                    None
                }
            }
            (true, 3) if self.is_render_name(toks[from].text, toks[from + 1].text) => {
                // `render <name> <camera> <file> ...`: renderers that name each render job.
                self.warn(
                    line,
                    At::Tok(from),
                    format!(
                        "`{}` is no camera but `{}` is: read as the render job's name, and skipped",
                        toks[from].text,
                        toks[from + 1].text
                    ),
                    Some(format!("canonical form: `{FORM_RENDER}`")),
                );
                camera = RenderCamera::Named;
                camera_at = Some(from + 1);
                Some(from + 2..names_end)
            }
            (true, _) => {
                camera = RenderCamera::Named;
                camera_at = Some(from);
                Some(from + 1..names_end)
            }
            (false, _) => Some(names.clone()),
        };
        if let Some(pieces) = file_pieces {
            output_at = At::Span(pieces.start, pieces.end.saturating_sub(1).max(pieces.start));
            match self.file_name(line, pieces.clone()) {
                Some(name) => output = Some(name),
                None => {
                    return Err(self.error(
                        line,
                        At::Span(from, names_end - 1),
                        format!(
                            "expected <camera> <file> before the image size, found {} names",
                            names.len()
                        ),
                        Some(format!("canonical form: `{FORM_RENDER}`")),
                    ));
                }
            }
        }
        Ok(RenderNames {
            camera,
            camera_at,
            output,
            output_at,
            tail,
        })
    }

    /// The image size from the numbers `nums` starting at token `at`; the default (with a
    /// note) when there are none.
    fn image_size(
        &mut self,
        line: &Line,
        at: usize,
        nums: &[f64],
        _notes: &mut Vec<String>,
    ) -> PResult<(u32, u32)> {
        match nums.len() {
            // Settled in `resolve_renders` (the camera line may give one).
            0 => Ok(DEFAULT_IMAGE_SIZE),
            1 => Err(self.error(
                line,
                At::End,
                "expected the image height, found end of line",
                Some(format!("canonical form: `{FORM_RENDER}`")),
            )),
            _ => {
                let (min, max) = (
                    f64::from(*limits::IMAGE_SIDE.start()),
                    f64::from(*limits::IMAGE_SIDE.end()),
                );
                let w = self.whole(line, at, nums[0], "image width", min, max);
                let h = self.whole(line, at + 1, nums[1], "image height", min, max);
                Ok((w?, h?))
            }
        }
    }

    /// The samples per pixel after the image size in `nums` (tokens `at..nums_end`), if
    /// given and usable.
    fn samples(
        &mut self,
        line: &Line,
        at: usize,
        nums_end: usize,
        nums: &[f64],
    ) -> PResult<Option<u32>> {
        if nums.len() > 3 {
            self.warn(
                line,
                At::Span(at + 2, nums_end - 1),
                format!("{} numbers after the image size ignored", nums.len() - 2),
                Some(format!(
                    "anim reads at most one: samples per pixel. canonical form: `{FORM_RENDER}`"
                )),
            );
        }
        if nums.len() != 3 {
            return Ok(None);
        }
        let s = self.whole(line, at + 2, nums[2], "sample count", 0.0, f64::MAX)?;
        if s == 0 {
            self.warn(
                line,
                At::Tok(at + 2),
                "0 samples per pixel; the default is used",
                None,
            );
            return Ok(None);
        }
        if !limits::SAMPLES.contains(&s) {
            let most = *limits::SAMPLES.end();
            self.warn(
                line,
                At::Tok(at + 2),
                format!("{s} samples per pixel is more than {most}; {most} used"),
                None,
            );
            return Ok(Some(most));
        }
        Ok(Some(s))
    }

    /// Whether a render line's first two names are a job's name and a camera: the first is no
    /// camera defined so far, the second is.
    fn is_render_name(&self, first: &str, second: &str) -> bool {
        let known = |n: &str| self.camera_names.iter().any(|c| c == n);
        !known(first) && known(second)
    }

    /// The output file name from the tokens `pieces`; a name broken by spaces around its
    /// dot (`image . ppm`, `image .ppm`) is joined with a warning. `None` if the pieces do not
    /// form one name.
    fn file_name(&mut self, line: &Line, pieces: std::ops::Range<usize>) -> Option<String> {
        let toks = &line.tokens;
        let parts: Vec<&str> = toks[pieces.clone()].iter().map(|t| t.text).collect();
        let (first, rest) = parts.split_first()?;
        let joinable = parts
            .windows(2)
            .all(|w| w[1].starts_with('.') || w[0].ends_with('.'));
        if rest.is_empty() {
            return Some((*first).to_string());
        }
        if !joinable {
            return None;
        }
        let joined = parts.concat();
        self.warn(
            line,
            At::Span(pieces.start, pieces.end - 1),
            format!(
                "file name written with spaces: `{}` is read as `{joined}`",
                parts.join(" ")
            ),
            None,
        );
        Some(joined)
    }

    /// A whole number in `[min, max]` at token `i`.
    fn whole(
        &mut self,
        line: &Line,
        i: usize,
        v: f64,
        what: &str,
        min: f64,
        max: f64,
    ) -> PResult<u32> {
        if v.fract() != 0.0 || v < min || v > max.min(u32::MAX as f64) {
            let range = if max >= u32::MAX as f64 {
                format!("a whole number of at least {min}")
            } else {
                format!("a whole number from {min} to {max}")
            };
            return Err(self.error(
                line,
                At::Tok(i),
                format!("the {what} must be {range}, found {v}"),
                Some(format!("canonical form: `{FORM_RENDER}`")),
            ));
        }
        Ok(v as u32)
    }
}

/// Whether a token looks like a file name rather than a (malformed) number: it holds a path
/// separator or an extension (`001.png`, `out/1.ppm`), unlike `1O` or `1.0f`.
fn file_like(t: &str) -> bool {
    t.contains('/')
        || t.contains('\\')
        || t.rsplit_once('.').is_some_and(|(_, ext)| {
            ext.len() >= 2 && ext.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        })
}

/// The index just past the names (camera, file) of a render line whose arguments start at
/// `from`. Names come first, then the numbers. A file name may start with a digit (`001.png`)
/// and a camera may be named by a number (`render 1 out.png ...`): a token is a name if it is
/// not number-like, looks like a file name, or is the first one and a name follows it.
fn names_end(line: &Line, from: usize) -> usize {
    let toks = &line.tokens;
    let is_name = |t: &str| !looks_numeric(t) || (file_like(t) && lexer::parse_number(t).is_err());
    let mut j = from;
    while j < toks.len()
        && (is_name(toks[j].text)
            || (j == from && toks.get(j + 1).is_some_and(|t| is_name(t.text))))
    {
        j += 1;
    }
    j
}
