//! Small helpers below everything else: atomic file writes and the clean-up of what an
//! interrupted one leaves, the one byte fingerprint ([`Fnv64`]), the one seeded generator of
//! test cases ([`SplitMix64`]) and the bit mixer they share with the sample patterns, and the
//! machine's memory.

use std::fs;
use std::io::{self, BufWriter};
use std::path::{Component, Path, PathBuf};

/// Suffix of the temporary files of [`write_atomically`]: `.NAME.PID.tmp`.
const TEMP_SUFFIX: &str = ".tmp";

/// Writes `contents` to `path` through a temporary file in the same directory and a rename,
/// so that `path` either keeps its old contents or has the complete new ones. A symbolic link
/// at `path` is replaced, never followed.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<fs::File>) -> io::Result<()>,
) -> io::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    fs::create_dir_all(dir)?;
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::other("output path has no file name"))?;
    let tmp = dir.join(format!(
        ".{}.{}{TEMP_SUFFIX}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut w = BufWriter::new(fs::File::create(&tmp)?);
        write(&mut w)?;
        // No fsync: the rename already guarantees that an interrupted process never leaves a
        // partial image under the final name, and syncing every frame costs ~0.1 s each.
        w.into_inner().map_err(|e| e.into_error())?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Removes the temporary files that [`write_atomically`] calls of processes that no longer
/// run (killed mid-write) from `dir`, and returns how many. Where the system cannot tell
/// whether a process runs (no `/proc`), nothing is removed.
pub fn remove_stale_temp_files(dir: &Path) -> io::Result<usize> {
    if !Path::new("/proc/self").exists() {
        return Ok(0);
    }
    let own = std::process::id();
    let mut removed = 0;
    for entry in fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(pid) = temp_file_owner(&name) else {
            continue;
        };
        let alive = pid == own || Path::new(&format!("/proc/{pid}")).exists();
        if !alive && entry.file_type()?.is_file() {
            fs::remove_file(entry.path())?;
            removed += 1;
        }
    }
    Ok(removed)
}

/// The process id in a temporary file name `.NAME.PID.tmp`.
fn temp_file_owner(name: &str) -> Option<u32> {
    let body = name.strip_prefix('.')?.strip_suffix(TEMP_SUFFIX)?;
    let (file, pid) = body.rsplit_once('.')?;
    if file.is_empty() || pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    pid.parse().ok()
}

/// FNV-1a, 64 bits: change detection, not security. The one fingerprint of bytes: frame
/// caches, written images, the bench's reference cache and the tests' golden manifest all use
/// it, so that one file hashed anywhere gives one number.
#[derive(Clone, Copy, Debug)]
pub struct Fnv64(u64);

impl Default for Fnv64 {
    fn default() -> Self {
        Fnv64(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv64 {
    /// Folds `bytes` into the fingerprint.
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    /// Folds `part` and then a separator byte, so that the parts ("ab", "c") and ("a", "bc")
    /// give different fingerprints.
    pub fn write_part(&mut self, part: &[u8]) {
        self.write(part);
        self.write(&[0xff]);
    }

    /// The fingerprint of everything written so far.
    pub fn finish(&self) -> u64 {
        self.0
    }

    /// The fingerprint of `bytes` alone.
    pub fn of(bytes: &[u8]) -> u64 {
        let mut h = Fnv64::default();
        h.write(bytes);
        h.finish()
    }
}

/// The finaliser of SplitMix64: a bijective mix of 64 bits in which every output bit depends
/// on every input bit. [`SplitMix64`] steps through it; the sample patterns derive their
/// per-pixel keys with it.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// SplitMix64 (Steele, Lea & Flood 2014): the one seeded generator of test cases, fuzz inputs
/// and the bench's fixed streams. Every seed, zero included, gives a full-period stream, so a
/// failure message that names its seed reproduces exactly. Nothing a user renders draws from
/// it.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// The stream of `seed`.
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix64(self.0)
    }

    /// Uniform in [0, 1), from the top 53 bits.
    pub fn unit_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [0, 1), from the top 24 bits.
    pub fn unit_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    /// Uniform in [`lo`, `hi`).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit_f64()
    }

    /// Below `n` (0 when `n` is 0), near enough to uniform for test cases.
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next_u64() % n as u64) as usize
        }
    }
}

/// A fast deterministic hasher for the reader's and the scene builder's tables of names
/// (the multiply-rotate hash of rustc's `FxHasher`): keys come from one file, not from an
/// adversary probing collisions, and std's SipHash is a noticeable share of loading a flat
/// file of a million shapes (docs/benchmarks-history.md §10).
#[derive(Clone, Copy, Debug, Default)]
pub struct FastHasher(u64);

const FAST_SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

impl FastHasher {
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(FAST_SEED);
    }
}

impl std::hash::Hasher for FastHasher {
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let mut word = [0u8; 8];
            word.copy_from_slice(c);
            self.add(u64::from_le_bytes(word));
        }
        let rest = chunks.remainder();
        if !rest.is_empty() {
            // The last byte holds the remainder's length, so `a` and `a\0` differ.
            let mut word = [0u8; 8];
            word[..rest.len()].copy_from_slice(rest);
            word[7] = rest.len() as u8;
            self.add(u64::from_le_bytes(word));
        }
    }

    fn write_u8(&mut self, i: u8) {
        self.add(u64::from(i));
    }

    fn write_u32(&mut self, i: u32) {
        self.add(u64::from(i));
    }

    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }

    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }

    fn finish(&self) -> u64 {
        // The multiply leaves the low bits, which pick the bucket, depending on the low
        // bytes of the key only (`s1`, `s2`, ... would share them); fold the high bits in.
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h
    }
}

/// Builds [`FastHasher`]s.
pub type FastHash = std::hash::BuildHasherDefault<FastHasher>;

/// A `HashMap` hashed with [`FastHasher`].
pub type FastMap<K, V> = std::collections::HashMap<K, V, FastHash>;

/// A `HashSet` hashed with [`FastHasher`].
pub type FastSet<K> = std::collections::HashSet<K, FastHash>;

/// The machine's physical memory in bytes, if the system says (Linux `/proc/meminfo`).
pub fn physical_memory() -> Option<u64> {
    let info = fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Whether the process can be given `bytes` more memory now: asked for and given back at once
/// (address space only; no page is touched). A budget says what anim may take; this says
/// what the system will give, which a limit set after start or a strict overcommit policy can
/// make less, and a refused allocation would otherwise end the process.
pub fn can_allocate(bytes: u64) -> bool {
    let Ok(bytes) = usize::try_from(bytes) else {
        return false;
    };
    Vec::<u8>::new().try_reserve_exact(bytes).is_ok()
}

/// The memory this process may use, in bytes: the least of the machine's physical memory,
/// the address-space limit it runs under (`ulimit -v`, `RLIMIT_AS`) and the memory limit of
/// its control group (cgroup v2 `memory.max`, v1 `memory.limit_in_bytes`); `None` when the
/// system says none of them. A limit the process cannot see would end it with an abort
/// rather than a message, so every one the system tells is counted.
pub fn memory_limit() -> Option<u64> {
    let limits = [
        physical_memory(),
        address_space_limit(),
        read_limit("/sys/fs/cgroup/memory.max"),
        read_limit("/sys/fs/cgroup/memory/memory.limit_in_bytes"),
    ];
    limits.into_iter().flatten().min()
}

/// The soft address-space limit of this process (`Max address space` of
/// `/proc/self/limits`), when there is one.
fn address_space_limit() -> Option<u64> {
    let limits = fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    line.trim_start_matches("Max address space")
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// A byte count written alone in a control-group file (`max`, or no file: no limit).
fn read_limit(path: &str) -> Option<u64> {
    fs::read_to_string(path).ok()?.trim().parse().ok()
}

/// `bytes` for messages: whole bytes below a KiB, then KiB, MiB or GiB with one decimal (a
/// tiny figure never reads as "0.0").
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [(&str, u32); 3] = [("GiB", 30), ("MiB", 20), ("KiB", 10)];
    let b = bytes as f64;
    match UNITS.iter().find(|(_, shift)| bytes >= 1u64 << shift) {
        Some((unit, shift)) => format!("{:.1} {unit}", b / (1u64 << shift) as f64),
        None if bytes == 1 => "1 byte".to_string(),
        None => format!("{bytes} bytes"),
    }
}

/// A path to `target` that reads the same from the directory `from` as `target` reads from
/// the current one: relative when both lie under one root, else absolute. Existing parts are
/// resolved (symbolic links followed), because `..` climbs out of where a link leads, not out
/// of the link; the parts of `from` that do not exist yet are taken as written.
pub fn path_from(from: &Path, target: &Path) -> io::Result<PathBuf> {
    let target = fs::canonicalize(target)?;
    let from = resolve_existing_prefix(from)?;
    let (t, f): (Vec<Component>, Vec<Component>) =
        (target.components().collect(), from.components().collect());
    if t.first() != f.first() {
        return Ok(target);
    }
    let common = t.iter().zip(&f).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..f.len() {
        out.push("..");
    }
    out.extend(&t[common..]);
    Ok(out)
}

/// `dir` made absolute, part by part: each part that exists is canonicalised (links followed)
/// before the next is added, and the parts that do not exist yet are taken as written
/// (`.` dropped, `..` taking off the part before, which cannot be a link since it does not
/// exist).
fn resolve_existing_prefix(dir: &Path) -> io::Result<PathBuf> {
    let mut resolved = PathBuf::new();
    for part in std::path::absolute(dir)?.components() {
        match part {
            Component::CurDir => {}
            // `resolved` is canonical wherever it exists, so its parent is the real one.
            Component::ParentDir => {
                resolved.pop();
            }
            _ => {
                resolved.push(part);
                if let Ok(real) = fs::canonicalize(&resolved) {
                    resolved = real;
                }
            }
        }
    }
    Ok(resolved)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_from_another_directory_reads_the_same_file() {
        let root = tempfile::tempdir().unwrap();
        let root = fs::canonicalize(root.path()).unwrap();
        let scenes = root.join("scenes/meshes");
        fs::create_dir_all(&scenes).unwrap();
        let mesh = scenes.join("tri.obj");
        fs::write(&mesh, "v 0 0 0\n").unwrap();
        // A frame directory that does not exist yet, named through `.` and `..`.
        let frames = root.join("anim/./frames/../frames/orbit");
        let rel = path_from(&frames, &mesh).unwrap();
        assert_eq!(rel, Path::new("../../../scenes/meshes/tri.obj"));
        fs::create_dir_all(&frames).unwrap();
        assert_eq!(fs::read(frames.join(&rel)).unwrap(), b"v 0 0 0\n");
        // From the mesh's own directory: the file name alone.
        assert_eq!(path_from(&scenes, &mesh).unwrap(), Path::new("tri.obj"));
    }

    #[cfg(unix)]
    #[test]
    fn a_path_from_inside_a_linked_directory_climbs_out_of_its_target() {
        let root = tempfile::tempdir().unwrap();
        let root = fs::canonicalize(root.path()).unwrap();
        fs::create_dir_all(root.join("real/deep")).unwrap();
        fs::create_dir_all(root.join("scenes")).unwrap();
        fs::write(root.join("scenes/m.obj"), "").unwrap();
        std::os::unix::fs::symlink(root.join("real/deep"), root.join("link")).unwrap();
        let frames = root.join("link/out");
        let rel = path_from(&frames, &root.join("scenes/m.obj")).unwrap();
        fs::create_dir_all(&frames).unwrap();
        assert!(frames.join(&rel).is_file(), "{rel:?} from {frames:?}");
    }

    #[test]
    fn bytes_read_in_mib_or_gib() {
        assert_eq!(human_bytes(3 << 20), "3.0 MiB");
        assert_eq!(human_bytes(1536 << 20), "1.5 GiB");
        assert_eq!(human_bytes(0), "0 bytes");
        assert_eq!(human_bytes(1), "1 byte");
        assert_eq!(human_bytes(1536), "1.5 KiB");
        assert_eq!(human_bytes(u64::MAX), "17179869184.0 GiB");
    }

    #[test]
    fn fnv_known_values() {
        // Published FNV-1a 64 test vectors.
        assert_eq!(Fnv64::default().finish(), 0xcbf29ce484222325);
        assert_eq!(Fnv64::of(b"a"), 0xaf63dc4c8601ec8c);
        assert_eq!(Fnv64::of(b"foobar"), 0x85944171f73967e8);
        let parts = |ps: &[&[u8]]| {
            let mut h = Fnv64::default();
            ps.iter().for_each(|p| h.write_part(p));
            h.finish()
        };
        assert_ne!(parts(&[b"ab", b"c"]), parts(&[b"a", b"bc"]));
    }

    #[test]
    fn splitmix64_gives_the_published_stream() {
        // The first outputs of seed 1234567 in the authors' reference implementation.
        let mut rng = SplitMix64::new(1_234_567);
        let first: Vec<u64> = (0..3).map(|_| rng.next_u64()).collect();
        assert_eq!(
            first,
            [
                6_457_827_717_110_365_317,
                3_203_168_211_198_807_973,
                9_817_491_932_198_370_423
            ]
        );
        let mut rng = SplitMix64::new(0);
        for _ in 0..10_000 {
            let (u, f, b) = (rng.unit_f64(), rng.unit_f32(), rng.below(7));
            assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&f) && b < 7);
        }
        assert_eq!(rng.below(0), 0);
    }

    #[test]
    fn the_fast_hasher_tells_names_apart_and_is_deterministic() {
        use std::hash::{BuildHasher, Hash, Hasher};
        let hash = |s: &str| FastHash::default().hash_one(s);
        assert_eq!(hash("s12"), hash("s12"));
        // Names that differ only past the first 8 bytes, or only in length.
        assert_ne!(hash("sphere_0001"), hash("sphere_0002"));
        assert_ne!(hash("s1"), hash("s1\0"));
        let mut set: FastSet<String> = FastSet::default();
        for i in 0..10_000 {
            assert!(set.insert(format!("s{i}")));
        }
        assert!(!set.insert("s9999".to_string()));
        let mut h = FastHasher::default();
        42u32.hash(&mut h);
        assert_ne!(h.finish(), 0);
    }

    #[test]
    fn temp_file_names_carry_their_owner() {
        assert_eq!(temp_file_owner(".frame_0001.png.4242.tmp"), Some(4242));
        assert_eq!(temp_file_owner(".x.1.tmp"), Some(1));
        for not_ours in [
            ".frame.png.tmp",
            "frame.4242.tmp",
            "..4242.tmp",
            ".a.b.tmp",
            ".a.12",
        ] {
            assert_eq!(temp_file_owner(not_ours), None, "{not_ours}");
        }
    }

    #[test]
    fn stale_temp_files_of_dead_processes_are_removed_and_others_kept() {
        let dir = tempfile::tempdir().unwrap();
        // Process ids are below 2^22 on Linux: this one cannot be running.
        let dead = dir.path().join(".frame.png.4294967.tmp");
        let ours = dir
            .path()
            .join(format!(".frame.png.{}.tmp", std::process::id()));
        let foreign = dir.path().join("holiday.4294967.tmp");
        for f in [&dead, &ours, &foreign] {
            fs::write(f, b"x").unwrap();
        }
        let removed = remove_stale_temp_files(dir.path()).unwrap();
        if Path::new("/proc/self").exists() {
            assert_eq!(removed, 1);
            assert!(!dead.exists());
        }
        assert!(ours.exists() && foreign.exists());
    }

    #[test]
    fn an_interrupted_write_leaves_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.txt");
        fs::write(&path, b"old").unwrap();
        let failed = write_atomically(&path, |w| {
            io::Write::write_all(w, b"new, half")?;
            Err(io::Error::other("interrupted"))
        });
        assert!(failed.is_err());
        assert_eq!(fs::read(&path).unwrap(), b"old");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
