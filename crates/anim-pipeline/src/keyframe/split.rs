//! The part of an animation that no frame changes, written once beside the frames
//! ([`STATIC_FILE`]) and included by each of them, so that a frame file holds only what is
//! keyed at its time (docs/animation.md, "Frame files").
//!
//! The split is found from the frames themselves, not from what the tracks say they touch:
//! a statement is about a *subject* (the name it defines or places; the ambient light, the
//! background, the render lines), and a subject is static when every frame holds exactly the
//! base scene's statements about it, in the base scene's order. A frame is then its static
//! statements (included first) followed by the others in the frame's own order. That moves
//! static statements ahead of keyed ones written before them in the base scene. Two statements
//! can trade places unless one of them defines or places a name the other defines, places or
//! refers to (a composite listing a child defined after it, a shape using a material defined
//! after it, a transform of a shape after its definition): such a static statement is kept in
//! the frames too, so the frames mean exactly what the whole files would. Two statements that
//! only refer to a common name (shapes drawn with one material, composites listing one
//! child) read it as the statements before both define it, whichever comes first, so they
//! trade places freely: a keyed shape defined before many still shapes of its material keeps
//! none of them in the frames.

use anim_core::sdf::ast::{Statement, StatementKind};
use std::collections::{HashMap, HashSet};

/// The static part's file name in the frame directory: not `.sdf`, so that `anim render DIR`
/// does not take it for a frame.
pub const STATIC_FILE: &str = "static.sdfi";

/// The subject of a statement about no name, written so that no name can equal it.
const AMBIENT: &str = "\u{0}ambient";
const BACKGROUND: &str = "\u{0}background";
const RENDER: &str = "\u{0}render";

/// What a statement is about (its subject, first) with the other names it defines or
/// places, and the names it only refers to.
fn names(kind: &StatementKind) -> (Vec<&str>, Vec<&str>) {
    match kind {
        StatementKind::Material(m) => (vec![&m.name], vec![]),
        StatementKind::Shape { name, material, .. } => (vec![name], vec![&material.name]),
        StatementKind::Composite { name, children } => (
            vec![name],
            children.iter().map(|c| c.name.as_str()).collect(),
        ),
        StatementKind::Light(l) => (vec![&l.name], vec![]),
        StatementKind::Ambient(_) | StatementKind::AmbientAdd(_) => (vec![AMBIENT], vec![]),
        StatementKind::Background(_) => (vec![BACKGROUND], vec![]),
        StatementKind::Camera(c) => (vec![&c.name], vec![]),
        StatementKind::Lens(l) => (vec![&l.camera.name], vec![]),
        StatementKind::Transform { target, .. } => (vec![&target.name], vec![]),
        StatementKind::Motion(m) => (vec![&m.target.name], vec![]),
        StatementKind::Render(r) => (vec![RENDER], vec![&r.camera.name]),
    }
}

fn subject(kind: &StatementKind) -> &str {
    names(kind).0[0]
}

/// The statements about each subject, in order (of the base scene, for
/// [`changed_subjects`]).
pub fn by_subject(statements: &[Statement]) -> HashMap<&str, Vec<&StatementKind>> {
    let mut groups: HashMap<&str, Vec<&StatementKind>> = HashMap::new();
    for s in statements {
        groups.entry(subject(&s.kind)).or_default().push(&s.kind);
    }
    groups
}

/// The subjects whose statements in `frame` are not exactly the base scene's (`base`, from
/// [`by_subject`]).
pub fn changed_subjects(
    base: &HashMap<&str, Vec<&StatementKind>>,
    frame: &[Statement],
) -> HashSet<String> {
    let groups = by_subject(frame);
    let mut changed: HashSet<String> = groups
        .iter()
        .filter(|(name, kinds)| base.get(*name) != Some(kinds))
        .map(|(name, _)| name.to_string())
        .collect();
    changed.extend(
        base.keys()
            .filter(|name| !groups.contains_key(*name))
            .map(|name| name.to_string()),
    );
    changed
}

/// The static part of an animation: the subjects no frame changes.
#[derive(Debug, Default)]
pub struct Split {
    static_subjects: HashSet<String>,
}

impl Split {
    /// The split of frames made from `base`, given every subject some frame changes.
    pub fn new(base: &[Statement], mut changed: HashSet<String>) -> Split {
        // Render lines are the frames' own, always.
        changed.insert(RENDER.to_string());
        // A static statement after a kept one about a common name stays in the frames (see
        // the module doc); that can keep another, so until nothing changes.
        loop {
            // What the kept statements so far define or place, and what they refer to.
            let mut kept_defined: HashSet<&str> = HashSet::new();
            let mut kept_read: HashSet<&str> = HashSet::new();
            let mut grew = false;
            for s in base {
                let (defined, read) = names(&s.kind);
                let subject = defined[0];
                let conflicts = defined
                    .iter()
                    .any(|n| kept_defined.contains(n) || kept_read.contains(n))
                    || read.iter().any(|n| kept_defined.contains(n));
                if !changed.contains(subject) && conflicts {
                    changed.insert(subject.to_string());
                    grew = true;
                }
                if changed.contains(subject) {
                    kept_defined.extend(defined);
                    kept_read.extend(read);
                }
            }
            if !grew {
                break;
            }
        }
        let static_subjects = base
            .iter()
            .map(|s| subject(&s.kind))
            .filter(|n| !changed.contains(*n))
            .map(str::to_string)
            .collect();
        Split { static_subjects }
    }

    /// Whether any statement is static.
    pub fn is_empty(&self) -> bool {
        self.static_subjects.is_empty()
    }

    /// Whether a statement belongs to the static part.
    pub fn is_static(&self, s: &Statement) -> bool {
        self.static_subjects.contains(subject(&s.kind))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim_core::sdf::{parse_source_whole, LoadOptions};
    use std::path::Path;

    /// The subjects left static when `keyed` are changed in the scene `text`.
    fn statics(text: &str, keyed: &[&str]) -> Vec<String> {
        let parsed = parse_source_whole(text, Path::new("t.sdf"), &LoadOptions::default());
        let changed = keyed.iter().map(|k| k.to_string()).collect();
        let split = Split::new(&parsed.statements, changed);
        let mut out: Vec<String> = parsed
            .statements
            .iter()
            .filter(|s| split.is_static(s))
            .map(|s| subject(&s.kind).to_string())
            .collect();
        out.dedup();
        out
    }

    const SCENE: &str = "define material m 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 1\n\
                         define shape sphere keyed 0 0 -5 1 m\n\
                         define shape sphere a 1 0 -5 1 m\n\
                         define shape composite group keyed a\n\
                         transform group translate 0 1 0\n\
                         define shape sphere b 2 0 -5 1 m\n";

    #[test]
    fn statements_that_only_share_a_reference_trade_places() {
        // `a` and `b` read `m` as `keyed` does; `group` lists `keyed` and its transform
        // places `group`, so both keep their places after `keyed`.
        assert_eq!(statics(SCENE, &["keyed"]), ["m", "a", "b"]);
    }

    #[test]
    fn what_refers_to_a_keyed_definition_stays_after_it() {
        // Every shape reads the keyed material; `group` lists `keyed`, then `group` is placed.
        assert_eq!(statics(SCENE, &["m"]), Vec::<String>::new());
        // A keyed child keeps the composite listing it and the transform of that composite.
        assert_eq!(statics(SCENE, &["a"]), ["m", "keyed", "b"]);
    }
}
