//! The bench's outputs: `bench.csv` (one row per scene × renderer × setting), `bench.md` (the
//! tables) and one time-against-error plot per scene.

use super::{plot, BenchReport, Row};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub const CSV_HEADER: &str = "scene,renderer,mode,setting,width,height,cpu_s,wall_s,rays,mean_spp,rmse,pct_over_1lsb,max_error,psnr_db";

/// PSNR as written: `inf` for an image equal to its reference.
fn psnr_text(db: f64) -> String {
    if db.is_finite() {
        format!("{db:.2}")
    } else {
        "inf".into()
    }
}

/// A CSV field: quoted when it holds a comma or a quote.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

pub fn csv(report: &BenchReport) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for r in &report.rows {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{:.6},{:.6},{},{},{:.6},{:.4},{},{}",
            field(&r.scene),
            r.renderer.name(),
            field(&r.mode),
            field(&r.setting),
            r.width,
            r.height,
            r.cpu_s,
            r.wall_s,
            r.rays.map(|n| n.to_string()).unwrap_or_default(),
            r.mean_spp.map(|n| format!("{n:.4}")).unwrap_or_default(),
            r.error.rmse,
            r.error.pct_over_1lsb,
            r.error.max_error,
            psnr_text(r.error.psnr_db),
        );
    }
    out
}

fn table_row(out: &mut String, r: &Row) {
    let _ = writeln!(
        out,
        "| {} | {} | {} | {:.3} | {:.3} | {} | {} | {:.3} | {:.2} | {} | {} |",
        r.renderer.name(),
        r.mode,
        r.setting,
        r.cpu_s,
        r.wall_s,
        r.rays
            .map(|n| format!("{:.2} M", n as f64 / 1e6))
            .unwrap_or_else(|| "–".into()),
        r.mean_spp
            .map(|n| format!("{n:.2}"))
            .unwrap_or_else(|| "–".into()),
        r.error.rmse,
        r.error.pct_over_1lsb,
        r.error.max_error,
        psnr_text(r.error.psnr_db),
    );
}

/// The tables, one per scene.
pub fn markdown(report: &BenchReport) -> String {
    let mut out = String::new();
    let clock = if report.whole_process {
        "CPU s: each renderer's whole process (user + system, GNU time): `anim render` reading, building, tracing and writing the image, and POV-Ray's render"
    } else {
        "CPU s: anim's process CPU time around the render call; POV-Ray's child process (user + system, whole process)"
    };
    let turns = match report.turns {
        1 => String::new(),
        n => format!(" Times are the median of {n} turns, all runs of a scene in turn."),
    };
    let _ = writeln!(
        out,
        "# anim bench: time against error\n\n{}×{}, {} threads. Error in 8-bit levels (after `c/(c+1)` and rounding) against each renderer's own converged image: anim uniform {} spp, POV-Ray `{}` (three HDR channel passes, tone-mapped alike; a scene with area lights or focal blur names its own below). {clock}.{turns}\n",
        report.width,
        report.height,
        report.threads,
        report.reference_spp,
        super::pov::REFERENCE_FLAGS,
    );
    for note in &report.notes {
        let _ = writeln!(out, "- {note}");
    }
    for scene in &report.scenes {
        let _ = writeln!(out, "\n## {} (`{}`)\n", scene.name, scene.file.display());
        for r in &scene.references {
            let how = match r.wall_s {
                Some(s) => format!("rendered in {s:.1} s"),
                None => "from the cache".into(),
            };
            let _ = writeln!(
                out,
                "- reference {}: {}, {how}",
                r.renderer.name(),
                r.setting
            );
        }
        let _ = writeln!(
            out,
            "\n| renderer | mode | setting | CPU s | wall s | rays | mean spp | RMSE | % > 1 LSB | max | PSNR dB |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"
        );
        for r in report.rows.iter().filter(|r| r.scene == scene.name) {
            table_row(&mut out, r);
        }
    }
    out
}

/// The per-pixel error estimate against the measured error, one line a bin: scene, setting,
/// the estimate's range (`kept`: not estimated), pixels, mean estimate, measured RMS.
fn calibration_tsv(report: &BenchReport) -> String {
    let mut out = String::from("scene\tsetting\testimate\tpixels\tmean_estimate\tmeasured_rms\n");
    for (scene, setting, bins) in &report.calibration {
        for b in bins {
            let range = b
                .estimate
                .map_or("kept".to_string(), |(lo, hi)| format!("{lo}-{hi}"));
            out.push_str(&format!(
                "{scene}\t{setting}\t{range}\t{}\t{:.3}\t{:.3}\n",
                b.pixels, b.mean_estimate, b.measured_rms
            ));
        }
    }
    out
}

/// Writes `bench.csv`, `bench.md`, `calibration.tsv`, `time-vs-error-<scene>.png` and, for
/// the scenes rendered adaptively, `estimate-vs-error-<scene>.png` into `dir`; returns the
/// files written.
pub fn write_outputs(report: &BenchReport, dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut written = Vec::new();
    let outputs = [
        ("bench.csv", csv(report)),
        ("bench.md", markdown(report)),
        ("calibration.tsv", calibration_tsv(report)),
    ];
    for (name, text) in outputs {
        let path = dir.join(name);
        write_text(&path, &text)?;
        written.push(path);
    }
    for scene in &report.scenes {
        let rows: Vec<&Row> = report
            .rows
            .iter()
            .filter(|r| r.scene == scene.name)
            .collect();
        let path = dir.join(format!("time-vs-error-{}.png", scene.name));
        plot::time_vs_error(&path, &scene.name, &rows)?;
        written.push(path);
        // The bins with an estimate (not the pixels that kept their centre sample).
        let settings: Vec<(&str, Vec<(f64, f64)>)> = report
            .calibration
            .iter()
            .filter(|(s, _, _)| *s == scene.name)
            .map(|(_, setting, bins)| {
                let points = bins
                    .iter()
                    .filter(|b| b.estimate.is_some() && b.mean_estimate.is_finite())
                    .map(|b| (b.mean_estimate, b.measured_rms));
                (setting.as_str(), points.collect())
            })
            .collect();
        if !settings.is_empty() {
            let path = dir.join(format!("estimate-vs-error-{}.png", scene.name));
            plot::estimate_vs_error(&path, &scene.name, &settings)?;
            written.push(path);
        }
    }
    Ok(written)
}

pub(crate) fn write_text(path: &Path, text: &str) -> Result<(), String> {
    anim_core::util::write_atomically(path, |w| std::io::Write::write_all(w, text.as_bytes()))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_are_quoted_when_needed() {
        assert_eq!(field("a b"), "a b");
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("a\"b"), "\"a\"\"b\"");
    }
}
