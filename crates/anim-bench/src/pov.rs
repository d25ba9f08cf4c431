//! POV-Ray's points on the bench: the same scenes through the converters of the shared tools
//! folder (`sdf2pov.py`, `povtonemap.py`), completed with the area lights and focal blur they
//! do not write ([`distributed`]).
//!
//! Time is POV-Ray's normal one-pass render (Phong scene, 8-bit PNG), as the CPU time of the
//! child process (user + system, from GNU `time -f %U+%S`). Error needs the tone mapping
//! anim uses, which POV-Ray cannot do itself: three grey HDR channel passes at the same
//! setting, merged with `c/(c+1)` by `povtonemap.py`, compared with the same merge of POV's
//! own converged render ([`reference_setting`]).

pub mod distributed;

use super::{
    cache_key, last_lines, metrics, read_rgb8, run_child, timed_process, BenchConfig, BenchScene,
    Reference, Renderer, Row, Timing, WorkDir, TIME,
};
use distributed::{Distributed, Sampling};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// One POV-Ray setting: anti-aliasing flags, and how finely area lights and focal blur sample.
#[derive(Clone, Debug, PartialEq)]
pub struct PovSetting {
    /// As written: POV-Ray's command-line flags and [`Sampling`]'s `NAME=VALUE` words.
    pub flags: String,
    /// The plot line it belongs to: no anti-aliasing (`no AA`), or adaptive method N (`AMN`),
    /// followed by `, adaptive N` when it names an area light's adaptive level.
    pub mode: String,
    /// The flags given to POV-Ray: `flags` without the sampling words.
    pub args: Vec<String>,
    pub sampling: Sampling,
}

impl PovSetting {
    /// The setting of `flags`, in the plot line of its anti-aliasing: on with the last `+A` or
    /// `+A<threshold>` that no `-A` follows, by method 1 unless a `+AM<n>` says otherwise.
    /// `Err` names a sampling word whose value is out of range.
    pub fn parse(flags: &str) -> Result<PovSetting, String> {
        let mut sampling = Sampling::default();
        let mut args = Vec::new();
        for word in flags.split_whitespace() {
            if !sampling.read_word(word)? {
                args.push(word.to_string());
            }
        }
        let switch = |w: &String| {
            let threshold = |rest: &str| rest.chars().all(|c| c.is_ascii_digit() || c == '.');
            match (w.strip_prefix("+A"), w.strip_prefix("-A")) {
                (Some(rest), _) if threshold(rest) => Some(true),
                (_, Some(rest)) if threshold(rest) => Some(false),
                _ => None,
            }
        };
        let on = args.iter().rev().find_map(switch).unwrap_or(false);
        let method = args
            .iter()
            .rev()
            .find_map(|w| w.strip_prefix("+AM"))
            .unwrap_or("1");
        let mut mode = if on {
            format!("AM{method}")
        } else {
            "no AA".to_string()
        };
        if let Some(level) = sampling.adaptive {
            mode += &format!(", adaptive {level}");
        }
        Ok(PovSetting {
            flags: flags.to_string(),
            mode,
            args,
            sampling,
        })
    }
}

/// Settings of flags known to be valid.
fn presets(flags: &[&str]) -> Vec<PovSetting> {
    flags
        .iter()
        .map(|f| PovSetting::parse(f).expect("a preset POV-Ray setting reads"))
        .collect()
}

/// Every setting of a full run.
pub fn standard_settings() -> Vec<PovSetting> {
    presets(&["-A", "+A0.3", "+A0.1", "+A0.3 +AM2 +R3", "+A0.1 +AM2 +R3"])
}

/// The quick run's: no anti-aliasing and the finest of each method.
pub fn quick_settings() -> Vec<PovSetting> {
    presets(&["-A", "+A0.1", "+A0.1 +AM2 +R3"])
}

/// POV-Ray's converged image of a scene of point lights and a pinhole.
pub const REFERENCE_FLAGS: &str = "+A0.0 +AM2 +R5";

/// Its anti-aliasing under a [`distributed::REFERENCE`] area light, whose 1089 shadow rays a
/// sample put [`REFERENCE_FLAGS`]' subdivision of every pixel out of reach: subdivision to the
/// same depth only where neighbouring samples differ (scripts/compare-pov.sh's threshold).
pub const AREA_REFERENCE_FLAGS: &str = "+A0.02 +AM2 +R5";

/// The flags and sampling of POV-Ray's converged image of a scene. Focal blur spreads its own
/// rays over each pixel, so a lens takes no anti-aliasing on top.
pub fn reference_setting(scene: &Distributed) -> (&'static str, Sampling) {
    let flags = if scene.has_lens() {
        "-A"
    } else if scene.is_empty() {
        REFERENCE_FLAGS
    } else {
        AREA_REFERENCE_FLAGS
    };
    (flags, distributed::REFERENCE)
}

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
fn povray(config: &BenchConfig, args: &[String], pov: &Path, out: &Path, hdr: bool) -> Command {
    let mut cmd = Command::new("povray");
    cmd.arg("-D")
        .arg(format!("+WT{}", config.threads.max(1)))
        .arg("File_Gamma=1.0")
        .arg(format!("+W{}", config.width))
        .arg(format!("+H{}", config.height))
        .arg(if hdr { "+FH" } else { "+FN" })
        .arg(format!("+O{}", out.display()))
        .args(args)
        .arg(pov);
    cmd
}

/// Converted scenes of one bench scene: the Phong scene and the three channel passes, as the
/// converter wrote them, and what completes them at a setting.
struct Converted {
    phong: String,
    channels: [String; 3],
    distributed: Distributed,
}

impl Converted {
    /// The three channel passes at `sampling`, written into `work`.
    fn channels_at(&self, sampling: &Sampling, work: &Path) -> Result<[PathBuf; 3], String> {
        let paths = ["r", "g", "b"].map(|c| work.join(format!("scene_{c}.pov")));
        for (text, path) in self.channels.iter().zip(&paths) {
            write(path, &self.distributed.complete(text, sampling)?)?;
        }
        Ok(paths)
    }
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

fn convert(
    tools: &Tools,
    scene: &BenchScene,
    config: &BenchConfig,
    work: &Path,
) -> Result<Converted, String> {
    let distributed = Distributed::of(&scene.job);
    // The converter reads the file itself; a scene with what it cannot read is given to it
    // without that, from the work folder.
    let sdf = if distributed.is_empty() {
        scene.file.clone()
    } else {
        let path = work.join("scene.sdf");
        write(
            &path,
            &distributed::strip(&String::from_utf8_lossy(&scene.bytes)),
        )?;
        path
    };
    let size = [
        "--width".to_string(),
        config.width.to_string(),
        "--height".to_string(),
        config.height.to_string(),
    ];
    let converted = |channel: Option<&str>| -> Result<String, String> {
        let out = work.join("converted.pov");
        let mut cmd = Command::new("python3");
        cmd.arg(&tools.sdf2pov).arg(&sdf).args(&size);
        if let Some(c) = channel {
            cmd.args(["--channel", c]);
        }
        run_child(cmd.arg("-o").arg(&out))?;
        std::fs::read_to_string(&out).map_err(|e| format!("cannot read {}: {e}", out.display()))
    };
    let phong = converted(None)?;
    let mut channels: [String; 3] = Default::default();
    for (c, text) in ["r", "g", "b"].iter().zip(&mut channels) {
        *text = converted(Some(c))?;
    }
    Ok(Converted {
        phong,
        channels,
        distributed,
    })
}

/// The tone-mapped 8-bit image of POV-Ray at `args` and `sampling`, written to `png`.
fn tone_mapped(
    tools: &Tools,
    conv: &Converted,
    config: &BenchConfig,
    (args, sampling): (&[String], &Sampling),
    work: &Path,
    png: &Path,
) -> Result<Vec<u8>, String> {
    let passes = conv.channels_at(sampling, work)?;
    // The three passes run at once: at bench sizes most of a POV-Ray process is its front
    // end waiting (about 0.7 s), not tracing, and these passes are not the timed ones.
    let hdrs: Vec<PathBuf> = (0..3).map(|i| work.join(format!("pass{i}.hdr"))).collect();
    let children: Vec<_> = passes
        .iter()
        .zip(&hdrs)
        .map(|(pov, hdr)| {
            povray(config, args, pov, hdr, true)
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

/// POV-Ray ready to time one scene: the converted scenes (the Phong one written at every
/// setting) and the converged reference, in a work folder of intermediate files removed with
/// the session (the reference is cached outside it).
pub struct Session<'a> {
    tools: &'a Tools,
    scene: &'a BenchScene,
    config: &'a BenchConfig,
    conv: Converted,
    /// The Phong scene of each setting, in the order of the settings.
    timed_scenes: Vec<PathBuf>,
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
        let mut timed_scenes = Vec::new();
        for (i, s) in config.pov_settings.iter().enumerate() {
            let path = work.0.join(format!("setting{i}.pov"));
            write(&path, &conv.distributed.complete(&conv.phong, &s.sampling)?)?;
            timed_scenes.push(path);
        }
        let (ref_flags, ref_sampling) = reference_setting(&conv.distributed);
        let ref_args: Vec<String> = ref_flags.split_whitespace().map(String::from).collect();
        let mut ref_label = ref_flags.to_string();
        let script = std::fs::read(&tools.sdf2pov).unwrap_or_default();
        let mut parts: Vec<Vec<u8>> = vec![
            scene.bytes.clone(),
            script,
            tools.version.as_bytes().to_vec(),
            ref_flags.as_bytes().to_vec(),
            config.width.to_le_bytes().to_vec(),
            config.height.to_le_bytes().to_vec(),
        ];
        // What completes the converter's scenes enters the key only where there is any, so
        // that the cached references of the other scenes stay valid.
        if !conv.distributed.is_empty() {
            ref_label += &format!(" {}", conv.distributed.words(&ref_sampling));
            for text in &conv.channels {
                parts.push(conv.distributed.complete(text, &ref_sampling)?.into_bytes());
            }
        }
        let key = cache_key(&parts.iter().map(Vec::as_slice).collect::<Vec<_>>());
        let ref_path = config
            .cache_dir
            .join(format!("{}-pov-{key:016x}.png", scene.name));
        let mut reference = Reference {
            renderer: Renderer::PovRay,
            setting: ref_label.clone(),
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
                    "{}: rendering the POV-Ray reference ({ref_label}, 3 channel passes)",
                    scene.name
                ));
                let start = Instant::now();
                let rgb = tone_mapped(
                    tools,
                    &conv,
                    config,
                    (&ref_args, &ref_sampling),
                    &work.0,
                    &ref_path,
                )?;
                reference.wall_s = Some(start.elapsed().as_secs_f64());
                rgb
            }
        };
        Ok(Session {
            tools,
            scene,
            config,
            conv,
            timed_scenes,
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
        for (s, pov) in self.config.pov_settings.iter().zip(&self.timed_scenes) {
            let cmd = povray(self.config, &s.args, pov, &out, false);
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
                (&s.args, &s.sampling),
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
        let mode = |flags: &str| PovSetting::parse(flags).unwrap().mode;
        assert_eq!(mode("-A"), "no AA");
        assert_eq!(mode(""), "no AA");
        assert_eq!(mode("+A0.3"), "AM1");
        assert_eq!(mode("+A"), "AM1");
        assert_eq!(mode("+A0.1 +AM2 +R3"), "AM2");
        // The last switch counts; a method alone does not turn anti-aliasing on.
        assert_eq!(mode("+A0.1 -A"), "no AA");
        assert_eq!(mode("+AM2 +R3"), "no AA");
        assert_eq!(
            PovSetting::parse("+A0.1 +AM2 +R3").unwrap().flags,
            "+A0.1 +AM2 +R3"
        );
    }

    #[test]
    fn sampling_words_are_kept_from_povrays_command_line() {
        let s = PovSetting::parse("-A area=9 adaptive=1 blur=16").unwrap();
        assert_eq!(s.args, ["-A"]);
        assert_eq!(s.mode, "no AA, adaptive 1");
        assert_eq!((s.sampling.area, s.sampling.blur), (9, 16));
        assert_eq!(PovSetting::parse("+A0.3 blur=8").unwrap().mode, "AM1");
        assert!(PovSetting::parse("-A area=0").is_err());
    }

    #[test]
    fn the_reference_takes_the_anti_aliasing_the_scene_affords() {
        let of = |extra: &str| {
            // A file without a render line renders its first camera.
            let text = format!(
                "define camera eye 60 0 1 5 0 0 -1 0 1 0\ndefine light key 0 5 0 1 1 1 1{extra}\n"
            );
            let loaded = anim_core::load::load_str(
                &text,
                Path::new("t.sdf"),
                &anim_core::sdf::LoadOptions::default(),
            )
            .unwrap_or_else(|d| panic!("{}", d[0]));
            let job = loaded.jobs.into_iter().next().unwrap();
            reference_setting(&Distributed::of(&job)).0
        };
        assert_eq!(of(""), REFERENCE_FLAGS);
        assert_eq!(of(" radius 1"), AREA_REFERENCE_FLAGS);
        assert_eq!(of("\nlens eye 0.1 5"), "-A");
    }
}
