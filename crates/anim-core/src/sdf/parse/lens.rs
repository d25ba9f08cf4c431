//! `lens <camera> <aperture> <focus>`: the thin lens of a camera (docs/scene-language.md
//! §6.1). Which camera it names is settled by the scene builder, once every camera of the
//! file and of the files it includes is known.

use super::{At, Parser};
use crate::sdf::ast::{LensDef, StatementKind};
use crate::sdf::lexer::Line;

const FORM: &str = "lens <camera> <aperture-radius> <focus-distance>";

impl Parser<'_> {
    /// `lens <camera> <aperture> <focus>`: an aperture radius of at least 0 (0 is a pinhole)
    /// and a focus distance above 0, both in scene units.
    pub(super) fn lens(&mut self, line: &Line) {
        let help = || Some(format!("canonical form: `{FORM}`"));
        let toks = &line.tokens;
        if toks.len() < 2 {
            self.error(
                line,
                At::End,
                "expected the name of a camera, found end of line",
                help(),
            );
            return;
        }
        let Ok(nums) = self.numbers(line, 2, toks.len()) else {
            return;
        };
        let [aperture, focus] = nums[..] else {
            let at = if nums.len() > 2 {
                At::Span(4, toks.len() - 1)
            } else {
                At::End
            };
            self.error(
                line,
                at,
                format!(
                    "a lens takes 2 numbers (aperture radius, focus distance), found {}",
                    nums.len()
                ),
                help(),
            );
            return;
        };
        if aperture < 0.0 {
            self.error(
                line,
                At::Tok(2),
                format!("a lens's aperture radius is at least 0 (0 is a pinhole), not {aperture}"),
                help(),
            );
            return;
        }
        if focus <= 0.0 {
            self.error(
                line,
                At::Tok(3),
                format!("the focus distance lies in front of the camera (above 0), not {focus}"),
                help(),
            );
            return;
        }
        let camera = self.name_ref(line, 1);
        let lens = LensDef {
            camera,
            aperture,
            focus,
        };
        self.emit_named(line, 1, StatementKind::Lens(lens));
    }
}

#[cfg(test)]
mod tests {
    use crate::diag::Severity;
    use crate::sdf::ast::StatementKind;
    use crate::sdf::{parse, LoadOptions};
    use std::path::Path;

    fn read(text: &str) -> (Vec<StatementKind>, Vec<crate::diag::Diagnostic>) {
        let (statements, ds) = parse(text, Path::new("s.sdf"), &LoadOptions::default());
        (statements.into_iter().map(|s| s.kind).collect(), ds)
    }

    #[test]
    fn a_lens_line_reads_back_as_written() {
        let (kinds, ds) = read("lens cam 0.25 12\n");
        assert!(ds.is_empty(), "{ds:?}");
        let lens = kinds.iter().find(|k| matches!(k, StatementKind::Lens(_)));
        assert_eq!(
            lens.map(|k| k.to_string()).as_deref(),
            Some("lens cam 0.25 12")
        );
    }

    #[test]
    fn bad_lenses_are_located_errors() {
        for (text, col, what) in [
            ("lens cam -1 12\n", 10, "at least 0"),
            ("lens cam 0.5 0\n", 14, "above 0"),
            ("lens cam 0.5\n", 13, "found 1"),
            ("lens cam 0.5 2 3\n", 16, "found 3"),
            ("lens\n", 5, "name of a camera"),
        ] {
            let (kinds, ds) = read(text);
            assert!(
                !kinds.iter().any(|k| matches!(k, StatementKind::Lens(_))),
                "{text}"
            );
            let e = ds
                .iter()
                .find(|d| d.severity == Severity::Error)
                .expect(text);
            assert!(e.message.contains(what), "{text}: {}", e.message);
            assert_eq!(e.loc.as_ref().map(|l| l.col), Some(col), "{text}");
        }
    }

    #[test]
    fn the_camera_takes_its_lens_and_an_aperture_of_0_is_a_pinhole() {
        let load = |lens: &str| {
            let text = format!("define camera c 60\n{lens}render c o.png 4 4\n");
            let loaded = crate::load::load_str(&text, Path::new("s.sdf"), &LoadOptions::default())
                .expect("loads");
            loaded.jobs[0].camera.lens
        };
        let lens = load("lens c 0.5 7\n").expect("a lens");
        assert_eq!((lens.aperture, lens.focus), (0.5, 7.0));
        assert_eq!(load("lens c 0 7\n"), None);
        assert_eq!(load(""), None);
    }
}
