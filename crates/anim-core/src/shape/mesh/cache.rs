//! Meshes shared between the scenes one process loads: the frames of an animation name the
//! same OBJ file again and again, and reading and building a million triangles costs far
//! more than tracing a small frame of them.
//!
//! An entry is keyed by the file's canonical path and a fingerprint of its bytes, so an OBJ
//! file edited between two loads is read again, and two names of one file share one mesh. A
//! mesh is immutable once built, so every scene holding it draws from the same arrays and
//! hierarchy and renders exactly as it would from a mesh of its own.

use super::Mesh;
use crate::diag::Diagnostic;
use crate::util::Fnv64;
use std::collections::HashMap;
use std::fmt;
use std::fs::File;
use std::io::{Read, Seek as _};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// What loading one file gave: the mesh, or the error every scene naming it reports.
type Outcome = Result<Arc<Mesh>, Box<Diagnostic>>;

/// The file a mesh came from: where it is and what it held.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct Key {
    path: PathBuf,
    len: u64,
    fingerprint: u64,
}

/// Loaded meshes, shared by every clone (clones of one `LoadOptions` share one cache). Two
/// scenes loading the same file at once wait for one reading of it.
#[derive(Clone, Default)]
pub struct MeshCache {
    entries: Arc<Mutex<HashMap<Key, Arc<OnceLock<Outcome>>>>>,
}

impl MeshCache {
    /// The mesh of the open OBJ file `file`, found at the real path `real`: from the cache
    /// when a file with the same real path and the same bytes was loaded before, else read
    /// with `load` and kept. A file over `max_bytes` is never read here: `load` refuses it.
    /// Both read the one open file, so what is kept is what was read.
    pub fn load(
        &self,
        file: &File,
        real: &Path,
        max_bytes: u64,
        load: impl FnOnce(&File) -> Outcome,
    ) -> Outcome {
        let Some(key) = key_of(file, real, max_bytes) else {
            // Unreadable or refused here: `load` says why, at the statement.
            return load(file);
        };
        let slot = {
            let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
            entries.entry(key).or_default().clone()
        };
        slot.get_or_init(|| load(file)).clone()
    }

    /// How many files the cache holds.
    pub fn len(&self) -> usize {
        self.entries.lock().map_or(0, |e| e.len())
    }

    /// Whether the cache holds no file.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The key of the open file `file` at `real`: its length and fingerprint, when it is a
/// regular text file of at most `max_bytes`; `None` when it cannot be read, is larger or
/// holds a NUL byte.
fn key_of(mut file: &File, real: &Path, max_bytes: u64) -> Option<Key> {
    let meta = file.metadata().ok()?;
    if !meta.is_file() || meta.len() > max_bytes {
        return None;
    }
    file.rewind().ok()?;
    let mut h = Fnv64::default();
    let mut buf = vec![0u8; 1 << 16];
    let mut len = 0u64;
    loop {
        let n = file.read(&mut buf).ok()?;
        if n == 0 {
            break;
        }
        // Not text: the loader refuses it at its first NUL, without this whole reading.
        if buf[..n].contains(&0) {
            return None;
        }
        h.write(&buf[..n]);
        len += n as u64;
    }
    Some(Key {
        path: real.to_path_buf(),
        len,
        fingerprint: h.finish(),
    })
}

/// A cache changes how often a file is read, never what a scene means: any two compare
/// equal, and all print alike (the frame pipeline's settings fingerprint prints the options).
impl PartialEq for MeshCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl fmt::Debug for MeshCache {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("MeshCache")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    const TETRAHEDRON: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
        f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

    /// Loads through `cache`, counting the readings.
    fn load(cache: &MeshCache, path: &Path, reads: &AtomicUsize) -> Outcome {
        let Ok(file) = File::open(path) else {
            reads.fetch_add(1, Ordering::SeqCst);
            return super::super::load(path, u64::MAX).map(Arc::new);
        };
        let real = path.canonicalize().unwrap();
        cache.load(&file, &real, u64::MAX, |f| {
            reads.fetch_add(1, Ordering::SeqCst);
            super::super::load_open(f, path, u64::MAX, u64::MAX).map(Arc::new)
        })
    }

    #[test]
    fn one_file_is_read_once_under_every_name_until_its_bytes_change() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.obj");
        std::fs::write(&path, TETRAHEDRON).unwrap();
        let cache = MeshCache::default();
        let shared = cache.clone();
        let reads = AtomicUsize::new(0);
        let a = load(&cache, &path, &reads).unwrap();
        let b = load(&shared, &dir.path().join(".").join("t.obj"), &reads).unwrap();
        assert!(Arc::ptr_eq(&a, &b));
        assert_eq!(reads.load(Ordering::SeqCst), 1);
        std::fs::write(&path, TETRAHEDRON.replace("v 0 0 1", "v 0 0 2")).unwrap();
        let c = load(&cache, &path, &reads).unwrap();
        assert!(!Arc::ptr_eq(&a, &c));
        assert_eq!((reads.load(Ordering::SeqCst), cache.len()), (2, 2));
    }

    #[test]
    fn an_error_is_reported_to_every_load_and_a_missing_file_is_never_kept() {
        let dir = tempfile::tempdir().unwrap();
        let bad = dir.path().join("bad.obj");
        std::fs::write(&bad, "v 0 0 0\n").unwrap();
        let cache = MeshCache::default();
        let reads = AtomicUsize::new(0);
        for _ in 0..2 {
            let e = load(&cache, &bad, &reads).unwrap_err();
            assert!(e.message.contains("no triangles"), "{}", e.message);
        }
        assert_eq!(reads.load(Ordering::SeqCst), 1);
        let missing = dir.path().join("missing.obj");
        assert!(load(&cache, &missing, &reads).is_err());
        assert_eq!((reads.load(Ordering::SeqCst), cache.len()), (2, 1));
    }

    #[test]
    fn scenes_loading_one_file_at_once_share_one_reading() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.obj");
        std::fs::write(&path, TETRAHEDRON).unwrap();
        let cache = MeshCache::default();
        let reads = AtomicUsize::new(0);
        let meshes: Vec<Arc<Mesh>> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..4)
                .map(|_| s.spawn(|| load(&cache, &path, &reads).unwrap()))
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert!(meshes.iter().all(|m| Arc::ptr_eq(m, &meshes[0])));
        assert_eq!(reads.load(Ordering::SeqCst), 1);
    }

    #[test]
    fn caches_compare_and_print_alike() {
        let (a, b) = (MeshCache::default(), MeshCache::default());
        assert_eq!(a, b);
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }
}
