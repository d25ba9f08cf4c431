//! Log-log plots (time against error; the sampler's error estimate against the measured
//! error), drawn by `plotters` into a pixel buffer with the bundled
//! DejaVu Sans (assets/fonts, Bitstream Vera licence), so no system font library is needed,
//! and encoded with the `image` crate the renderer already uses.

use super::{Renderer, Row};
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

const FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
const SIZE: (u32, u32) = (800, 560);

/// plotters' `ab_glyph` text looks fonts up by family name; the default family of labels is
/// "sans-serif".
fn register_font() -> Result<(), String> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
                .map_err(|_| "the bundled font cannot be read".to_string())
        })
        .clone()
}

fn colour(renderer: Renderer, mode: &str) -> RGBColor {
    match (renderer, mode) {
        (Renderer::Anim, "uniform") => RGBColor(0x1f, 0x77, 0xb4),
        (Renderer::Anim, _) => RGBColor(0x2c, 0xa0, 0x2c),
        (Renderer::PovRay, "no AA") => RGBColor(0x7f, 0x7f, 0x7f),
        (Renderer::PovRay, "AM1") => RGBColor(0xff, 0x7f, 0x0e),
        (Renderer::PovRay, _) => RGBColor(0xd6, 0x27, 0x28),
    }
}

/// Plots RMSE against CPU seconds, one line per renderer and mode. Values are clamped to
/// small positive floors because a log axis cannot show 0 (an exact image, or a render
/// shorter than the clock's tick).
pub fn time_vs_error(path: &Path, scene: &str, rows: &[&Row]) -> Result<(), String> {
    const MIN_S: f64 = 1e-4;
    const MIN_RMSE: f64 = 1e-3;
    let lines: Vec<PlotLine> = series(rows)
        .into_iter()
        .map(|((renderer, mode), mut line)| {
            line.sort_by(|a, b| a.cpu_s.total_cmp(&b.cpu_s));
            PlotLine {
                label: format!("{} {mode}", renderer.name()),
                colour: colour(renderer, &mode),
                points: line
                    .iter()
                    .map(|r| (r.cpu_s.max(MIN_S), r.error.rmse.max(MIN_RMSE)))
                    .collect(),
                dots: true,
            }
        })
        .collect();
    let all = lines.iter().flat_map(|l| l.points.iter().copied());
    let (x, y) = padded_bounds(all).unwrap_or(((MIN_S, 1.0), (MIN_RMSE, 1.0)));
    let chart = LogLog {
        caption: format!("{scene}: time against error"),
        axes: ("CPU seconds", "RMSE (8-bit levels)"),
        x,
        y,
        legend: SeriesLabelPosition::UpperRight,
    };
    chart.draw(path, &lines)
}

/// Plots, per adaptive setting, the sampler's per-pixel error estimate where each pixel
/// stopped against the error measured there: one point per bin of pixels (mean estimate,
/// measured RMS error; `metrics::calibration`), log-log, with the line on which the estimate
/// would be exact.
pub fn estimate_vs_error(
    path: &Path,
    scene: &str,
    settings: &[(&str, Vec<(f64, f64)>)],
) -> Result<(), String> {
    const FLOOR: f64 = 1e-2;
    let mut lines: Vec<PlotLine> = settings
        .iter()
        .enumerate()
        .map(|(i, (setting, points))| PlotLine {
            label: setting.to_string(),
            colour: SETTING_COLOURS[i % SETTING_COLOURS.len()],
            points: points
                .iter()
                .map(|&(x, y)| (x.max(FLOOR), y.max(FLOOR)))
                .collect(),
            dots: true,
        })
        .collect();
    // Both axes span the same range, so that the exact line is the diagonal.
    let all = lines.iter().flat_map(|l| l.points.iter().copied());
    let ((x0, x1), (y0, y1)) = padded_bounds(all).unwrap_or(((FLOOR, 10.0), (FLOOR, 10.0)));
    let (lo, hi) = (x0.min(y0), x1.max(y1));
    lines.insert(
        0,
        PlotLine {
            label: "estimate exact".into(),
            colour: RGBColor(0x7f, 0x7f, 0x7f),
            points: vec![(lo, lo), (hi, hi)],
            dots: false,
        },
    );
    let chart = LogLog {
        caption: format!("{scene}: estimated against measured error per pixel"),
        axes: (
            "mean estimate of the bin (8-bit levels)",
            "measured RMS error (8-bit levels)",
        ),
        x: (lo, hi),
        y: (lo, hi),
        legend: SeriesLabelPosition::UpperLeft,
    };
    chart.draw(path, &lines)
}

/// One line of a plot: its legend label, colour and points; `dots` marks each point (and
/// draws the line wider).
struct PlotLine {
    label: String,
    colour: RGBColor,
    points: Vec<(f64, f64)>,
    dots: bool,
}

/// A log-log chart: its caption, the names of its axes, their ranges and where the legend
/// goes.
struct LogLog {
    caption: String,
    axes: (&'static str, &'static str),
    x: (f64, f64),
    y: (f64, f64),
    legend: SeriesLabelPosition,
}

impl LogLog {
    /// Draws `lines` on this chart and writes it to `path` as a PNG.
    fn draw(self, path: &Path, lines: &[PlotLine]) -> Result<(), String> {
        register_font()?;
        let LogLog {
            caption,
            axes,
            x,
            y,
            legend,
        } = self;
        let (x, y) = (x.0..x.1, y.0..y.1);
        draw_png(path, |root, err| {
            let mut chart = ChartBuilder::on(root)
                .caption(caption, ("sans-serif", 22).into_font())
                .margin(14)
                .x_label_area_size(44)
                .y_label_area_size(64)
                .build_cartesian_2d(x.log_scale(), y.log_scale())
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc(axes.0)
                .y_desc(axes.1)
                .x_label_formatter(&|v| short(*v))
                .y_label_formatter(&|v| short(*v))
                .light_line_style(RGBColor(236, 236, 236))
                .draw()
                .map_err(err)?;
            for line in lines {
                let c = line.colour;
                let width = if line.dots { 2 } else { 1 };
                chart
                    .draw_series(LineSeries::new(line.points.clone(), c.stroke_width(width)))
                    .map_err(err)?
                    .label(line.label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
                if line.dots {
                    let dots = line.points.iter().map(|&p| Circle::new(p, 4, c.filled()));
                    chart.draw_series(dots).map_err(err)?;
                }
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(legend)
                .draw()
                .map_err(err)?;
            Ok(())
        })
    }
}

/// The ranges of `points` in x and in y, each widened by half a decade on both sides so that
/// end points stay off the frame; `None` without points.
fn padded_bounds(points: impl Iterator<Item = (f64, f64)>) -> Option<((f64, f64), (f64, f64))> {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in points {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    (x0 <= x1).then_some(((x0 / 1.6, x1 * 1.6), (y0 / 1.6, y1 * 1.6)))
}

/// One colour per adaptive setting of a calibration plot, dark enough to read on white.
const SETTING_COLOURS: [RGBColor; 6] = [
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xff, 0x7f, 0x0e),
];

/// The error type of drawing into the bitmap, as the plots see it.
type DrawError = DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>;

/// Draws one chart (`draw` gets the white drawing area and the error's converter) into a
/// bitmap of `SIZE` and writes it to `path` as a PNG.
fn draw_png(
    path: &Path,
    draw: impl FnOnce(
        &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
        &dyn Fn(DrawError) -> String,
    ) -> Result<(), String>,
) -> Result<(), String> {
    let mut buf = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let err = |e: DrawError| format!("plot {}: {e:?}", path.display());
        let root = BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        draw(&root, &err)?;
        root.present().map_err(err)?;
    }
    let rgb = image::RgbImage::from_raw(SIZE.0, SIZE.1, buf)
        .ok_or_else(|| "plot buffer has the wrong size".to_string())?;
    let mut png = std::io::Cursor::new(Vec::new());
    rgb.write_to(&mut png, image::ImageFormat::Png)
        .map_err(|e| format!("cannot encode {}: {e}", path.display()))?;
    anim_core::util::write_atomically(path, |w| std::io::Write::write_all(w, png.get_ref()))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// An axis number without trailing zeros: 0.01, 2, 150.
fn short(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() || s == "-" {
        "0".into()
    } else {
        s.to_string()
    }
}

/// Plot lines: rows grouped by renderer and mode, in first-seen order.
fn series<'a>(rows: &[&'a Row]) -> Vec<((Renderer, String), Vec<&'a Row>)> {
    let mut out: Vec<((Renderer, String), Vec<&Row>)> = Vec::new();
    for &r in rows {
        let key = (r.renderer, r.mode.clone());
        match out.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(r),
            None => out.push((key, vec![r])),
        }
    }
    out
}
