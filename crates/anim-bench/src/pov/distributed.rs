//! Soft shadows and depth of field in POV-Ray: the statements the shared converter
//! (`sdf2pov.py`) does not write. It is given the scene without them (a spherical light's
//! `radius` clause and `lens` lines left out: the point light and the pinhole it knows), and its
//! output is completed here: a spherical light becomes an `area_light`, a lens `focal_blur`.

use anim_core::scene::RenderJob;
use glam::DVec3;

/// How finely POV-Ray samples the area lights and the lens of a scene: the `NAME=VALUE` words
/// of a `--pov-setting`, beside its command-line flags.
#[derive(Clone, Debug, PartialEq)]
pub struct Sampling {
    /// Rows (and columns) of an area light's grid of samples (`area=N`).
    pub area: u32,
    /// The area light's `adaptive` level (`adaptive=N`): POV-Ray first samples a
    /// (2^N + 1)-square subgrid and subdivides only where its corners disagree. `None` takes
    /// every sample of the grid.
    pub adaptive: Option<u32>,
    /// The most rays focal blur traces in a pixel (`blur=N`, POV-Ray's `blur_samples`).
    pub blur: u32,
    /// Focal blur stops adding rays to a pixel once, with this `confidence` (`confidence=X`),
    /// the variance of its mean is below `variance` (`variance=X`).
    pub confidence: f64,
    pub variance: f64,
}

impl Default for Sampling {
    /// What a setting that says nothing of them gets: a 9×9 area light taken whole, and focal
    /// blur of up to 32 rays with POV-Ray's default confidence and variance.
    fn default() -> Sampling {
        Sampling {
            area: 9,
            adaptive: None,
            blur: 32,
            confidence: 0.9,
            variance: 1.0 / 128.0,
        }
    }
}

/// POV-Ray's converged soft shadows and depth of field: a 33×33 area light taken whole (as
/// scripts/compare-pov.sh holds it against anim's spherical light), focal blur of up to 1024
/// rays a pixel stopping only where their mean is known to a variance of 10⁻⁶.
pub const REFERENCE: Sampling = Sampling {
    area: 33,
    adaptive: None,
    blur: 1024,
    confidence: 0.9999,
    variance: 1e-6,
};

impl Sampling {
    /// Reads one `NAME=VALUE` word into `self`: `Ok(false)` when the word is not one of
    /// them (a POV-Ray option), `Err` when its value is out of range.
    pub fn read_word(&mut self, word: &str) -> Result<bool, String> {
        let Some((name, value)) = word.split_once('=') else {
            return Ok(false);
        };
        let bad = |what: &str| format!("'{word}': {name} takes {what}");
        let count = |lo: u32, hi: u32| {
            value
                .parse::<u32>()
                .ok()
                .filter(|n| (lo..=hi).contains(n))
                .ok_or_else(|| bad(&format!("a whole number from {lo} to {hi}")))
        };
        let fraction = || {
            value
                .parse::<f64>()
                .ok()
                .filter(|x| *x > 0.0 && *x < 1.0)
                .ok_or_else(|| bad("a number between 0 and 1"))
        };
        match name {
            // 2 is the least that is a grid; 65 (the next 2^n + 1 above the reference's 33)
            // bounds a typing slip's cost.
            "area" => self.area = count(2, 65)?,
            "adaptive" => self.adaptive = Some(count(0, 6)?),
            "blur" => self.blur = count(1, 4096)?,
            "confidence" => self.confidence = fraction()?,
            "variance" => self.variance = fraction()?,
            _ => return Ok(false),
        }
        Ok(true)
    }
}

/// POV-Ray 3.7 draws focal blur's rays from a disc of radius 0.5 scaled by half its `aperture`
/// (`JitterCameraRay`): its aperture is four times the radius of the lens it simulates.
const APERTURE_PER_RADIUS: f64 = 4.0;

/// What the converter leaves out of a scene's render job: its spherical lights (name and
/// radius) and its camera's lens (POV-Ray's aperture and the point in focus on the view axis).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Distributed {
    lights: Vec<(String, f64)>,
    lens: Option<(f64, DVec3)>,
}

impl Distributed {
    pub fn of(job: &RenderJob) -> Distributed {
        let camera = &job.camera;
        Distributed {
            lights: job
                .scene
                .lights
                .iter()
                .filter(|l| l.radius > 0.0)
                .map(|l| (l.name.clone(), l.radius))
                .collect(),
            lens: camera.lens.as_ref().map(|lens| {
                let focus = camera.eye + camera.dir.normalize() * lens.focus;
                (APERTURE_PER_RADIUS * lens.aperture, focus)
            }),
        }
    }

    /// Whether the scene has neither: the converter's output is then the scene.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty() && self.lens.is_none()
    }

    pub fn has_lens(&self) -> bool {
        self.lens.is_some()
    }

    /// The words of `sampling` that this scene heeds, as [`Sampling::read_word`] reads them.
    pub fn words(&self, sampling: &Sampling) -> String {
        let mut words = Vec::new();
        if !self.lights.is_empty() {
            words.push(format!("area={}", sampling.area));
            if let Some(n) = sampling.adaptive {
                words.push(format!("adaptive={n}"));
            }
        }
        if self.lens.is_some() {
            words.push(format!(
                "blur={} confidence={} variance={}",
                sampling.blur, sampling.confidence, sampling.variance
            ));
        }
        words.join(" ")
    }

    /// The converter's output `pov` with every spherical light made an area light and the
    /// camera given focal blur, sampled as `sampling` says.
    pub fn complete(&self, pov: &str, sampling: &Sampling) -> Result<String, String> {
        let mut lines: Vec<String> = pov.lines().map(str::to_string).collect();
        for (name, radius) in &self.lights {
            // The converter writes each light on one line, named in its closing comment.
            let comment = format!("}}  // {name}");
            let line = lines
                .iter_mut()
                .find(|l| l.starts_with("light_source {") && l.ends_with(&comment))
                .ok_or_else(|| format!("the converted scene has no light_source '{name}'"))?;
            let d = 2.0 * radius;
            let n = sampling.area;
            let mut area =
                format!("area_light <{d}, 0, 0>, <0, 0, {d}>, {n}, {n} circular orient jitter");
            if let Some(level) = sampling.adaptive {
                area += &format!(" adaptive {level}");
            }
            let at = line.len() - comment.len();
            line.insert_str(at, &format!("{area} "));
        }
        if let Some((aperture, focus)) = self.lens {
            let start = lines
                .iter()
                .position(|l| l.trim_start().starts_with("camera {"))
                .ok_or("the converted scene has no camera")?;
            let end = start
                + lines[start..]
                    .iter()
                    .position(|l| l.trim() == "}")
                    .ok_or("the converted scene's camera has no end")?;
            lines.insert(
                end,
                format!(
                    "  aperture {aperture} focal_point <{}, {}, {}> blur_samples {} confidence {} variance {}",
                    focus.x, focus.y, focus.z, sampling.blur, sampling.confidence, sampling.variance
                ),
            );
        }
        Ok(lines.join("\n") + "\n")
    }
}

/// `sdf` without what the converter cannot read: the `radius <r>` clause of every light and
/// every `lens` line (left as an empty line, so that the converter's line numbers stay right).
pub fn strip(sdf: &str) -> String {
    let mut out = String::with_capacity(sdf.len());
    for line in sdf.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["lens", ..] => {}
            ["define", "light", ..] => {
                let mut kept: Vec<&str> = Vec::with_capacity(words.len());
                let mut i = 0;
                while i < words.len() {
                    if words[i] == "radius" && i + 1 < words.len() {
                        i += 2;
                    } else {
                        kept.push(words[i]);
                        i += 1;
                    }
                }
                out += &kept.join(" ");
            }
            _ => out += line,
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim_core::sdf::LoadOptions;
    use std::path::Path;

    const SCENE: &str = "\
define material m 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1
define shape sphere ball 0 1 -10 1 m
define light key -3 9 -6 1 1 1 1.2 radius 1.5
define light fill 5 5 5 1 1 1 0.5
define camera eye 50 0 2 2 0 -0.1 -1 0 1 0
lens eye 0.25 10
render eye out.png 32 18
";

    fn job(text: &str) -> RenderJob {
        let loaded = anim_core::load::load_str(text, Path::new("t.sdf"), &LoadOptions::default())
            .unwrap_or_else(|d| panic!("{}", d[0]));
        loaded.jobs.into_iter().next().unwrap()
    }

    /// The parts of the converter's output that `complete` works on, as it writes them.
    const CONVERTED: &str = "\
camera {
  perspective
  location <0, 2, 2>
}
light_source { <-3, 9, -6> color rgb <1.2, 1.2, 1.2> }  // key
light_source { <5, 5, 5> color rgb <0.5, 0.5, 0.5> }  // fill
";

    #[test]
    fn the_converter_is_given_point_lights_and_a_pinhole() {
        let stripped = strip(SCENE);
        assert!(stripped.contains("define light key -3 9 -6 1 1 1 1.2\n"));
        assert!(stripped.contains("define light fill 5 5 5 1 1 1 0.5\n"));
        assert!(!stripped.contains("lens"));
        // Line numbers of the converter's messages stay those of the file.
        assert_eq!(stripped.lines().count(), SCENE.lines().count());
        let plain = job(&stripped);
        assert!(plain.scene.lights.iter().all(|l| l.radius == 0.0));
        assert!(plain.camera.lens.is_none());
        assert!(Distributed::of(&plain).is_empty());
    }

    #[test]
    fn a_spherical_light_becomes_a_disc_of_its_diameter_and_a_lens_focal_blur() {
        let d = Distributed::of(&job(SCENE));
        let sampling = Sampling {
            area: 17,
            adaptive: Some(2),
            blur: 64,
            confidence: 0.95,
            variance: 0.001,
        };
        let pov = d.complete(CONVERTED, &sampling).unwrap();
        // Diameter 2 × 1.5; the point light stays as it was.
        assert!(pov.contains(
            "light_source { <-3, 9, -6> color rgb <1.2, 1.2, 1.2> area_light <3, 0, 0>, \
             <0, 0, 3>, 17, 17 circular orient jitter adaptive 2 }  // key\n"
        ));
        assert!(pov.contains("light_source { <5, 5, 5> color rgb <0.5, 0.5, 0.5> }  // fill\n"));
        // Aperture 4 × 0.25; in focus 10 along the view (0, -0.1, -1) from the eye (0, 2, 2).
        let f = DVec3::new(0.0, 2.0, 2.0) + 10.0 * DVec3::new(0.0, -0.1, -1.0).normalize();
        let blur = format!(
            "  aperture 1 focal_point <{}, {}, {}> blur_samples 64 confidence 0.95 variance 0.001\n}}\n",
            f.x, f.y, f.z
        );
        assert!(
            pov.contains(&format!("  location <0, 2, 2>\n{blur}")),
            "{pov}"
        );
        assert!((f - DVec3::new(0.0, 1.004963, -7.950372)).length() < 1e-6);
        assert_eq!(
            d.words(&sampling),
            "area=17 adaptive=2 blur=64 confidence=0.95 variance=0.001"
        );
        // Without an adaptive level, every sample of the grid is taken.
        let whole = d.complete(CONVERTED, &Sampling::default()).unwrap();
        assert!(whole.contains(", 9, 9 circular orient jitter }  // key"));
    }

    #[test]
    fn a_scene_without_them_is_the_converters_output() {
        let d = Distributed::default();
        assert_eq!(d.complete(CONVERTED, &REFERENCE).unwrap(), CONVERTED);
        assert_eq!(d.words(&REFERENCE), "");
        // A light the converter did not write is an error, not a silent point light.
        let missing = Distributed::of(&job(SCENE)).complete("camera {\n}\n", &REFERENCE);
        assert!(missing.unwrap_err().contains("'key'"));
    }

    #[test]
    fn sampling_words_are_read_and_checked() {
        let mut s = Sampling::default();
        assert_eq!(s.read_word("+A0.3"), Ok(false));
        assert_eq!(s.read_word("File_Gamma=1.0"), Ok(false));
        assert_eq!(s.read_word("area=5"), Ok(true));
        assert_eq!(s.read_word("adaptive=1"), Ok(true));
        assert_eq!(s.read_word("blur=128"), Ok(true));
        assert_eq!(s.read_word("confidence=0.99"), Ok(true));
        assert_eq!(s.read_word("variance=0.0001"), Ok(true));
        assert_eq!(
            s,
            Sampling {
                area: 5,
                adaptive: Some(1),
                blur: 128,
                confidence: 0.99,
                variance: 0.0001
            }
        );
        for bad in [
            "area=1",
            "area=x",
            "adaptive=7",
            "blur=0",
            "confidence=1",
            "variance=0",
        ] {
            assert!(s.read_word(bad).is_err(), "{bad}");
        }
    }
}
