//! POV-Ray's points on the bench: the same scenes through the converters of the shared tools
//! folder (`sdf2pov.py`, `povtonemap.py`).
//!
//! Time is POV-Ray's normal one-pass render (Phong scene, 8-bit PNG), as the CPU time of the
//! child process (user + system, from GNU `time -f %U+%S`). Error needs the tone mapping
//! anim uses, which POV-Ray cannot do itself: three grey HDR channel passes at the same
//! setting, merged with `c/(c+1)` by `povtonemap.py`, compared with the same merge of POV's
//! own converged render (`+A0.0 +AM2 +R5`).

use super::{cache_key, metrics, read_rgb8, BenchConfig, BenchScene, Reference, Renderer, Row};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// One POV-Ray anti-aliasing setting.
#[derive(Clone, Debug, PartialEq)]
pub struct PovSetting {
    /// Its command-line flags, as written in the report.
    pub flags: &'static str,
    /// The plot line it belongs to: no anti-aliasing, or adaptive method 1 or 2.
    pub mode: &'static str,
}

const fn setting(flags: &'static str, mode: &'static str) -> PovSetting {
    PovSetting { flags, mode }
}

/// Every setting of a full run.
pub fn standard_settings() -> Vec<PovSetting> {
    vec![
        setting("-A", "no AA"),
        setting("+A0.3", "AM1"),
        setting("+A0.1", "AM1"),
        setting("+A0.3 +AM2 +R3", "AM2"),
        setting("+A0.1 +AM2 +R3", "AM2"),
    ]
}

/// The quick run's: no anti-aliasing and the finest of each method.
pub fn quick_settings() -> Vec<PovSetting> {
    vec![
        setting("-A", "no AA"),
        setting("+A0.1", "AM1"),
        setting("+A0.1 +AM2 +R3", "AM2"),
    ]
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

const TIME: &str = "/usr/bin/time";

/// The end of a failed program's messages, where the reason is.
fn last_lines(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(8)..].join(" | ")
}

fn run(cmd: &mut Command) -> Result<String, String> {
    let out = cmd
        .output()
        .map_err(|e| format!("cannot run {cmd:?}: {e}"))?;
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    if !out.status.success() {
        return Err(format!(
            "{:?} failed ({}): {}",
            cmd.get_program(),
            out.status,
            last_lines(&stderr)
        ));
    }
    Ok(stderr)
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
    run(Command::new("python3")
        .arg(&tools.sdf2pov)
        .arg(&scene.file)
        .args(&size)
        .arg("-o")
        .arg(&phong))?;
    let channels = ["r", "g", "b"].map(|c| work.join(format!("scene_{c}.pov")));
    for (c, path) in ["r", "g", "b"].iter().zip(&channels) {
        run(Command::new("python3")
            .arg(&tools.sdf2pov)
            .arg(&scene.file)
            .args(&size)
            .args(["--channel", c])
            .arg("-o")
            .arg(path))?;
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
    run(Command::new("python3")
        .arg(&tools.tonemap)
        .args(&hdrs)
        .arg("-o")
        .arg(png))?;
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

/// Times POV-Ray at every setting on one scene and measures each against its converged image.
pub fn measure_scene(
    tools: &Tools,
    scene: &BenchScene,
    config: &BenchConfig,
    progress: &mut dyn FnMut(&str),
) -> Result<(Reference, Vec<Row>), String> {
    let work = config
        .cache_dir
        .join(format!("pov-work-{}-{}", std::process::id(), scene.name));
    std::fs::create_dir_all(&work).map_err(|e| format!("cannot create {}: {e}", work.display()))?;
    let result = measure_in(tools, scene, config, &work, progress);
    // The work folder holds only intermediate files; the reference is cached outside it.
    let _ = std::fs::remove_dir_all(&work);
    result
}

fn measure_in(
    tools: &Tools,
    scene: &BenchScene,
    config: &BenchConfig,
    work: &Path,
    progress: &mut dyn FnMut(&str),
) -> Result<(Reference, Vec<Row>), String> {
    let conv = convert(tools, scene, config, work)?;
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
            let rgb = tone_mapped(tools, &conv, config, REFERENCE_FLAGS, work, &ref_path)?;
            reference.wall_s = Some(start.elapsed().as_secs_f64());
            rgb
        }
    };
    let mut rows = Vec::new();
    for s in &config.pov_settings {
        let out = work.join("timed.png");
        let times = work.join("time.txt");
        let wall = Instant::now();
        let stderr = run(Command::new(TIME)
            .arg("-o")
            .arg(&times)
            .args(["-f", "%U+%S"])
            .arg("povray")
            .args(povray(config, s.flags, &conv.phong, &out, false).get_args()))?;
        let wall_s = wall.elapsed().as_secs_f64();
        let cpu_s = read_time(&times)?;
        let rgb = tone_mapped(
            tools,
            &conv,
            config,
            s.flags,
            work,
            &work.join("setting.png"),
        )?;
        let pixels = f64::from(config.width) * f64::from(config.height);
        let row = Row {
            scene: scene.name.clone(),
            renderer: Renderer::PovRay,
            mode: s.mode.to_string(),
            setting: s.flags.to_string(),
            width: config.width,
            height: config.height,
            cpu_s,
            wall_s,
            // POV-Ray's "Rays" leave out shadow rays, so they are not comparable with anim's.
            rays: None,
            // POV-Ray counts the samples of anti-aliasing only; without it, one per pixel.
            mean_spp: match stat(&stderr, "Samples:") {
                Some(n) if n > 0 => Some(n as f64 / pixels),
                _ => Some(1.0),
            },
            error: metrics::compare_rgb8(&rgb, &ref_rgb),
        };
        progress(&super::row_line(&row));
        rows.push(row);
    }
    Ok((reference, rows))
}

/// Reads GNU time's `%U+%S` output (user + system seconds of the child).
fn read_time(path: &Path) -> Result<f64, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let line = text
        .lines()
        .rev()
        .find(|l| l.contains('+'))
        .ok_or_else(|| format!("no time in {}", path.display()))?;
    let (u, s) = line.trim().split_once('+').unwrap_or((line, "0"));
    let parse = |x: &str| {
        x.trim()
            .parse::<f64>()
            .map_err(|_| format!("bad time '{line}' in {}", path.display()))
    };
    Ok(parse(u)? + parse(s)?)
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
}
