//! POV-Ray's points on the bench: the same scenes through the converters of the shared tools
//! folder (`sdf2pov.py`, `povtonemap.py`).
//!
//! Time is POV-Ray's normal one-pass render (Phong scene, 8-bit PNG), as the CPU time of the
//! child process (user + system, from GNU `time -f %U+%S`). Error needs the tone mapping
//! anim uses, which POV-Ray cannot do itself: three grey HDR channel passes at the same
//! setting, merged with `c/(c+1)` by `povtonemap.py`, compared with the same merge of POV's
//! own converged render (`+A0.0 +AM2 +R5`).

use super::{
    cache_key, last_lines, metrics, read_rgb8, run_child, timed_process, BenchConfig, BenchScene,
    Reference, Renderer, Row, Timing, WorkDir, TIME,
};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// One POV-Ray anti-aliasing setting.
#[derive(Clone, Debug, PartialEq)]
pub struct PovSetting {
    /// Its command-line flags, as written in the report.
    pub flags: String,
    /// The plot line it belongs to: no anti-aliasing (`no AA`), or adaptive method N (`AMN`).
    pub mode: String,
}

impl PovSetting {
    /// The setting of `flags`, in the plot line of its anti-aliasing: on with the last `+A` or
    /// `+A<threshold>` that no `-A` follows, by method 1 unless a `+AM<n>` says otherwise.
    pub fn new(flags: &str) -> PovSetting {
        let words: Vec<&str> = flags.split_whitespace().collect();
        let switch = |w: &&str| {
            let threshold = |rest: &str| rest.chars().all(|c| c.is_ascii_digit() || c == '.');
            match (w.strip_prefix("+A"), w.strip_prefix("-A")) {
                (Some(rest), _) if threshold(rest) => Some(true),
                (_, Some(rest)) if threshold(rest) => Some(false),
                _ => None,
            }
        };
        let on = words.iter().rev().find_map(switch).unwrap_or(false);
        let method = words
            .iter()
            .rev()
            .find_map(|w| w.strip_prefix("+AM"))
            .unwrap_or("1");
        PovSetting {
            flags: flags.to_string(),
            mode: if on {
                format!("AM{method}")
            } else {
                "no AA".to_string()
            },
        }
    }
}

/// Every setting of a full run.
pub fn standard_settings() -> Vec<PovSetting> {
    ["-A", "+A0.3", "+A0.1", "+A0.3 +AM2 +R3", "+A0.1 +AM2 +R3"]
        .map(PovSetting::new)
        .to_vec()
}

/// The quick run's: no anti-aliasing and the finest of each method.
pub fn quick_settings() -> Vec<PovSetting> {
    ["-A", "+A0.1", "+A0.1 +AM2 +R3"]
        .map(PovSetting::new)
        .to_vec()
}

/// POV-Ray's converged image.
pub const REFERENCE_FLAGS: &str = "+A0.0 +AM2 +R5";

/// What running POV-Ray needs, all found.
#[derive(Clone, Debug)]
pub struct Tools {
    pub sdf2pov: PathBuf,
    pub tonemap: PathBuf,
    /// `povray --version`'s first line, part of the reference cache key.
    pub version: String,
}

impl Tools {
    /// Looks for the converters in `dir`, and for `povray`, `python3` and GNU `time`.
    /// `Err` says what is missing.
    pub fn find(dir: &Path) -> Result<Tools, String> {
        let sdf2pov = dir.join("sdf2pov.py");
        let tonemap = dir.join("povtonemap.py");
        for f in [&sdf2pov, &tonemap] {
            if !f.is_file() {
                return Err(format!("{} not found (see --pov-tools)", f.display()));
            }
        }
        let out = Command::new("povray")
            .arg("--version")
            .output()
            .map_err(|_| "povray is not installed".to_string())?;
        let text = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        let version = text
            .lines()
            .find(|l| l.starts_with("POV-Ray"))
            .unwrap_or("POV-Ray (unknown version)")
            .to_string();
        if Command::new("python3").arg("--version").output().is_err() {
            return Err("python3 is not installed".into());
        }
        if !Path::new(TIME).is_file() {
            return Err(format!("{TIME} (GNU time) is not installed"));
        }
        Ok(Tools {
            sdf2pov,
            tonemap,
            version,
        })
    }
}

/// The POV-Ray command for one render of `pov` into `out`.
fn povray(config: &BenchConfig, flags: &str, pov: &Path, out: &Path, hdr: bool) -> Command {
    let mut cmd = Command::new("povray");
    cmd.arg("-D")
        .arg(format!("+WT{}", config.threads.max(1)))
        .arg("File_Gamma=1.0")
        .arg(format!("+W{}", config.width))
        .arg(format!("+H{}", config.height))
        .arg(if hdr { "+FH" } else { "+FN" })
        .arg(format!("+O{}", out.display()))
        .args(flags.split_whitespace())
        .arg(pov);
    cmd
}

/// Converted scenes of one bench scene: the Phong scene and the three channel passes.
struct Converted {
    phong: PathBuf,
    channels: [PathBuf; 3],
}

fn convert(
    tools: &Tools,
    scene: &BenchScene,
    config: &BenchConfig,
    work: &Path,
) -> Result<Converted, String> {
    let size = [
        "--width".to_string(),
        config.width.to_string(),
        "--height".to_string(),
        config.height.to_string(),
    ];
    let phong = work.join("scene.pov");
    run_child(
        Command::new("python3")
            .arg(&tools.sdf2pov)
            .arg(&scene.file)
            .args(&size)
            .arg("-o")
            .arg(&phong),
    )?;
    let channels = ["r", "g", "b"].map(|c| work.join(format!("scene_{c}.pov")));
    for (c, path) in ["r", "g", "b"].iter().zip(&channels) {
        run_child(
            Command::new("python3")
                .arg(&tools.sdf2pov)
                .arg(&scene.file)
                .args(&size)
                .args(["--channel", c])
                .arg("-o")
                .arg(path),
        )?;
    }
    Ok(Converted { phong, channels })
}

/// The tone-mapped 8-bit image of POV-Ray at `flags`, written to `png`.
fn tone_mapped(
    tools: &Tools,
    conv: &Converted,
    config: &BenchConfig,
    flags: &str,
    work: &Path,
    png: &Path,
) -> Result<Vec<u8>, String> {
    // The three passes run at once: at bench sizes most of a POV-Ray process is its front
    // end waiting (about 0.7 s), not tracing, and these passes are not the timed ones.
    let hdrs: Vec<PathBuf> = (0..3).map(|i| work.join(format!("pass{i}.hdr"))).collect();
    let children: Vec<_> = conv
        .channels
        .iter()
        .zip(&hdrs)
        .map(|(pov, hdr)| {
            povray(config, flags, pov, hdr, true)
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .map_err(|e| format!("cannot run povray: {e}"))
        })
        .collect();
    let mut failure = None;
    for child in children {
        let out = child.and_then(|c| {
            c.wait_with_output()
                .map_err(|e| format!("povray did not finish: {e}"))
        });
        let problem = match out {
            Ok(o) if o.status.success() => continue,
            Ok(o) => format!(
                "povray failed ({}): {}",
                o.status,
                last_lines(&String::from_utf8_lossy(&o.stderr))
            ),
            Err(e) => e,
        };
        // Wait for every child before reporting, so none is left running.
        failure.get_or_insert(problem);
    }
    if let Some(problem) = failure {
        return Err(problem);
    }
    run_child(
        Command::new("python3")
            .arg(&tools.tonemap)
            .args(&hdrs)
            .arg("-o")
            .arg(png),
    )?;
    read_rgb8(png, config.width, config.height)
        .ok_or_else(|| format!("cannot read POV-Ray's merged image {}", png.display()))
}

/// A number after `label` in POV-Ray's statistics (e.g. `Samples:           13086`).
fn stat(text: &str, label: &str) -> Option<u64> {
    text.lines().find_map(|l| {
        let rest = &l[l.find(label)? + label.len()..];
        rest.split_whitespace().next()?.parse().ok()
    })
}

/// POV-Ray ready to time one scene: the converted scenes and the converged reference, in a
/// work folder of intermediate files removed with the session (the reference is cached
/// outside it).
pub struct Session<'a> {
    tools: &'a Tools,
    scene: &'a BenchScene,
    config: &'a BenchConfig,
    conv: Converted,
    ref_rgb: Vec<u8>,
    pub reference: Reference,
    work: WorkDir,
}

impl<'a> Session<'a> {
    /// Converts the scene and finds POV-Ray's converged image in the cache, or renders it.
    pub fn start(
        tools: &'a Tools,
        scene: &'a BenchScene,
        config: &'a BenchConfig,
        progress: &mut dyn FnMut(&str),
    ) -> Result<Session<'a>, String> {
        let work = WorkDir::new(config, "pov", scene)?;
        let conv = convert(tools, scene, config, &work.0)?;
        let script = std::fs::read(&tools.sdf2pov).unwrap_or_default();
        let key = cache_key(&[
            &scene.bytes,
            &script,
            tools.version.as_bytes(),
            REFERENCE_FLAGS.as_bytes(),
            &config.width.to_le_bytes(),
            &config.height.to_le_bytes(),
        ]);
        let ref_path = config
            .cache_dir
            .join(format!("{}-pov-{key:016x}.png", scene.name));
        let mut reference = Reference {
            renderer: Renderer::PovRay,
            setting: REFERENCE_FLAGS.to_string(),
            wall_s: None,
            path: ref_path.clone(),
        };
        let ref_rgb = match read_rgb8(&ref_path, config.width, config.height) {
            Some(rgb) => {
                progress(&format!(
                    "{}: POV-Ray reference from cache {}",
                    scene.name,
                    ref_path.display()
                ));
                rgb
            }
            None => {
                progress(&format!(
                    "{}: rendering the POV-Ray reference ({REFERENCE_FLAGS}, 3 channel passes)",
                    scene.name
                ));
                let start = Instant::now();
                let rgb = tone_mapped(tools, &conv, config, REFERENCE_FLAGS, &work.0, &ref_path)?;
                reference.wall_s = Some(start.elapsed().as_secs_f64());
                rgb
            }
        };
        Ok(Session {
            tools,
            scene,
            config,
            conv,
            ref_rgb,
            reference,
            work,
        })
    }

    /// One turn: POV-Ray's normal render at every setting, each timed as a whole process
    /// (GNU time), with its mean samples per pixel.
    pub fn time_all(&self) -> Result<Vec<(Timing, f64)>, String> {
        let pixels = f64::from(self.config.width) * f64::from(self.config.height);
        let out = self.work.0.join("timed.png");
        let report = self.work.0.join("time.txt");
        let mut timed = Vec::new();
        for s in &self.config.pov_settings {
            let cmd = povray(self.config, &s.flags, &self.conv.phong, &out, false);
            let (stderr, timing) = timed_process(&cmd, &report)?;
            // POV-Ray counts the samples of anti-aliasing only; without it, one per pixel.
            let spp = match stat(&stderr, "Samples:") {
                Some(n) if n > 0 => n as f64 / pixels,
                _ => 1.0,
            };
            timed.push((timing, spp));
        }
        Ok(timed)
    }

    /// The rows of every setting, given its time and mean samples per pixel (in the order of
    /// the settings), each with its error against the converged image.
    pub fn rows(&self, timed: impl Iterator<Item = (Timing, f64)>) -> Result<Vec<Row>, String> {
        let mut rows = Vec::new();
        for (s, (timing, spp)) in self.config.pov_settings.iter().zip(timed) {
            let png = self.work.0.join("setting.png");
            let rgb = tone_mapped(
                self.tools,
                &self.conv,
                self.config,
                &s.flags,
                &self.work.0,
                &png,
            )?;
            rows.push(Row {
                scene: self.scene.name.clone(),
                renderer: Renderer::PovRay,
                mode: s.mode.clone(),
                setting: s.flags.clone(),
                width: self.config.width,
                height: self.config.height,
                cpu_s: timing.cpu_s,
                wall_s: timing.wall_s,
                // POV-Ray's "Rays" leave out shadow rays, so they are not comparable with anim's.
                rays: None,
                mean_spp: Some(spp),
                error: metrics::compare_rgb8(&rgb, &self.ref_rgb),
            });
        }
        Ok(rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_are_read() {
        let text = "Pixels:             5538   Samples:           13086   Smpls/Pxl: 2.36\n";
        assert_eq!(stat(text, "Samples:"), Some(13086));
        assert_eq!(stat(text, "Pixels:"), Some(5538));
        assert_eq!(stat(text, "Rays:"), None);
    }

    #[test]
    fn a_setting_is_drawn_in_the_line_of_its_method() {
        let mode = |flags: &str| PovSetting::new(flags).mode;
        assert_eq!(mode("-A"), "no AA");
        assert_eq!(mode(""), "no AA");
        assert_eq!(mode("+A0.3"), "AM1");
        assert_eq!(mode("+A"), "AM1");
        assert_eq!(mode("+A0.1 +AM2 +R3"), "AM2");
        // The last switch counts; a method alone does not turn anti-aliasing on.
        assert_eq!(mode("+A0.1 -A"), "no AA");
        assert_eq!(mode("+AM2 +R3"), "no AA");
        assert_eq!(PovSetting::new("+A0.1 +AM2 +R3").flags, "+A0.1 +AM2 +R3");
    }
}
