//! What a scene may make anim read, held against a scene that tries to read more: a file
//! swapped for a link to a secret while anim opens it, the current directory at `/` or the
//! home folder, and messages that would tell whether a file outside exists.

use crate::common::anim;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

const HEAD: &str = "define material m 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1\n\
    define light l 0 5 5 1 1 1 1\n\
    define camera c 60\n";

const SECRET: &str = "TOPSECRET";

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

/// Runs `anim check scene.sdf` in `dir` `runs` times while another thread keeps replacing
/// `target` by a file of `benign` text and by a link to a file of secret lines outside the
/// folder; the number of runs whose output held a secret line.
fn race(dir: &Path, target: &Path, benign: &str, secret: &Path, runs: usize) -> usize {
    let stop = AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| {
            let next = target.with_extension("next");
            let mut link = false;
            while !stop.load(Ordering::Relaxed) {
                let _ = std::fs::remove_file(&next);
                if link {
                    std::os::unix::fs::symlink(secret, &next).unwrap();
                } else {
                    std::fs::write(&next, benign).unwrap();
                }
                std::fs::rename(&next, target).unwrap();
                link = !link;
            }
        });
        let leaks = (0..runs)
            .filter(|_| {
                let out = anim()
                    .current_dir(dir)
                    .args(["check", "scene.sdf"])
                    .output()
                    .unwrap();
                let all = [out.stdout, out.stderr].concat();
                String::from_utf8_lossy(&all).contains(SECRET)
            })
            .count();
        stop.store(true, Ordering::Relaxed);
        leaks
    })
}

/// A secret file whose every line, read as a scene or as an OBJ file, would be quoted.
fn secret_file(dir: &Path) -> std::path::PathBuf {
    let secret = dir.join("secret.txt");
    let lines: String = (0..20).map(|i| format!("v {SECRET}{i} 1 2 3\n")).collect();
    write(&secret, &lines);
    secret
}

/// An included file swapped for a link to a secret, 800 times while anim reads it: its
/// diagnostics (from the reader, and from the builder quoting the file's lines afterwards)
/// never quote the secret. The file is judged by what was opened, and quoted only while it
/// holds the bytes that were read.
#[test]
fn an_include_swapped_for_a_link_to_a_secret_never_shows_it() {
    let tmp = tempfile::tempdir().unwrap();
    let secret = secret_file(tmp.path());
    let dir = tmp.path().join("project");
    write(
        &dir.join("scene.sdf"),
        &format!("{HEAD}include part.sdfi\nrender c out.png 8 6\n"),
    );
    let benign = "bogus line here\ndefine shape sphere s 0 0 -5 1 nomaterial\n";
    let leaks = race(&dir, &dir.join("part.sdfi"), benign, &secret, 800);
    assert_eq!(leaks, 0);
}

/// The same race on a mesh: an OBJ problem quotes its line, never the secret's.
#[test]
fn a_mesh_swapped_for_a_link_to_a_secret_never_shows_it() {
    let tmp = tempfile::tempdir().unwrap();
    let secret = secret_file(tmp.path());
    let dir = tmp.path().join("project");
    write(
        &dir.join("scene.sdf"),
        &format!("{HEAD}define shape obj t part.obj m\nrender c out.png 8 6\n"),
    );
    let benign = "v 0 0 -5\nv 1 0 -5\nv 0 1 -5\nf 1 2 3\nv x 0 0\n";
    let leaks = race(&dir, &dir.join("part.obj"), benign, &secret, 800);
    assert_eq!(leaks, 0);
}

/// Run from `/`, a scene in a folder of its own cannot read `/etc/passwd` through the
/// current directory: `/` is never a root. Nothing of the file is printed.
#[test]
fn the_root_folder_is_never_a_root_of_what_a_scene_reads() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().canonicalize().unwrap();
    let up = "../".repeat(dir.components().count() - 1);
    let passwd = std::fs::read_to_string("/etc/passwd").unwrap_or_default();
    for include in [format!("{up}etc/passwd"), "/etc/passwd".to_string()] {
        write(
            &dir.join("scene.sdf"),
            &format!("{HEAD}include {include}\nrender c out.png 8 6\n"),
        );
        let out = anim()
            .current_dir("/")
            .arg("check")
            .arg(dir.join("scene.sdf").strip_prefix("/").unwrap())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains("is outside the scene's folder"), "{stderr}");
        for line in passwd.lines().filter(|l| !l.is_empty()) {
            assert!(!stderr.contains(line), "{line} in {stderr}");
        }
    }
}

/// The home folder is no root either: run from it, a scene in a folder below it cannot read
/// a file beside that folder.
#[test]
fn the_home_folder_is_never_a_root_of_what_a_scene_reads() {
    let tmp = tempfile::tempdir().unwrap();
    let home = tmp.path().canonicalize().unwrap();
    write(&home.join(".secrets.sdfi"), "ambient 1 1 1\n");
    write(
        &home.join("project/scene.sdf"),
        &format!("{HEAD}include ../.secrets.sdfi\nrender c out.png 8 6\n"),
    );
    let out = anim()
        .current_dir(&home)
        .env("HOME", &home)
        .args(["check", "project/scene.sdf"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("`../.secrets.sdfi` is outside the scene's folder"),
        "{stderr}"
    );
}

/// Outside the folders, a file that exists and one that does not get the same message (the
/// name aside), for an include and for a mesh alike.
#[test]
fn messages_do_not_tell_whether_a_file_outside_exists() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("project");
    // Names of one length, so that the carets under them match too.
    write(&tmp.path().join("here.sdfi"), "ambient 1 1 1\n");
    write(&tmp.path().join("here.obj"), "v 0 0 0\n");
    let message = |line: &str, name: &str| {
        write(
            &dir.join("scene.sdf"),
            &format!("{HEAD}{line}\nrender c out.png 8 6\n"),
        );
        let out = anim()
            .current_dir(&dir)
            .args(["check", "scene.sdf"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1));
        String::from_utf8_lossy(&out.stderr).replace(name, "NAME")
    };
    for (here, gone) in [
        ("include ../here.sdfi", "include ../gone.sdfi"),
        (
            "define shape obj t ../here.obj m",
            "define shape obj t ../gone.obj m",
        ),
    ] {
        let a = message(here, "here");
        let b = message(gone, "gone");
        assert_eq!(a, b);
        assert!(a.contains("is outside"), "{a}");
    }
}
