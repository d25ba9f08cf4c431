//! The shapes of a flat file, kept apart by the reader (`sdf::ast::FlatShapes`: nothing in
//! the file refers to a shape by name), built into instances without being made into
//! statements and definitions first. The scene and the diagnostics are those the statements
//! would give (`scene::scale_tests` compares the two); the shapes are turned into instances
//! chunk by chunk, each chunk freed once done, so the file's shapes are never held twice.

use super::definitions::Definitions;
use super::jobs::{placed_geometry, Expansion, Flat, Largest};
use super::{At, Builder};
use crate::scene::{Instance, Names, RenderJob, NO_NAME};
use crate::sdf::ast::{FlatShapes, NameRef, Statement, StatementKind};
use crate::shape::degeneracy;
use crate::util::{FastHash, FastSet};
use std::collections::HashMap;
use std::hash::BuildHasher;
use std::sync::Arc;

impl Builder<'_> {
    /// The jobs of `statements` (none of them a shape) and the flat `shapes`.
    pub(super) fn flat_jobs(
        &mut self,
        statements: &[Statement],
        mut shapes: FlatShapes,
    ) -> Vec<RenderJob> {
        // Made before the definitions, which borrow them.
        let unknown = unknown_material_uses(statements, &shapes);
        let first_def = material_first_defs(statements);
        let mut d = self.definitions(statements);
        self.check_cycles(&d);
        let uses: Vec<(&NameRef, &str)> = unknown.iter().map(|(m, s)| (m, s.as_str())).collect();
        let fallback_of = self.undefined_materials(&mut d, &uses);
        let resolved: Vec<Option<usize>> = (0..shapes.material_count())
            .map(|id| {
                let name = shapes.material_name(id);
                d.material_index
                    .get(name)
                    .or_else(|| fallback_of.get(name))
                    .copied()
            })
            .collect();

        let state = self.flat_shape_states(&shapes, &resolved, &d, &first_def);
        let mut total = Expansion::default();
        let mut first_root: Option<usize> = None;
        // What is drawn: every shape, but those of a material that cannot be resolved and
        // the degenerate ones.
        for (k, &st) in state.iter().enumerate() {
            first_root.get_or_insert(k);
            total.nodes += 1;
            total.shapes += u64::from(st == DRAWABLE);
        }
        let snapshots = self.snapshots(statements, &d);
        let fits = match first_root.and_then(|k| shapes.get(k)) {
            Some(s) => {
                let (loc, width) = shapes.name_place(s);
                let largest = Largest {
                    name: shapes.name(s),
                    composite: false,
                    at: At::Place(&loc, width),
                };
                self.fits(total, &largest, snapshots.len() as u64)
            }
            None => Some(0),
        };

        let (instances, names) = match fits {
            Some(count) => {
                let count = usize::try_from(count).unwrap_or(0);
                flat_instances(&mut shapes, &state, &resolved, count)
            }
            None => (Vec::new(), Names::default()),
        };
        drop(state);
        drop(shapes);
        let flat = Flat {
            instances: Arc::new(instances),
            slots: Vec::new(),
            names: Arc::new(names),
            // A flat file has no composites, so nothing is kept once.
            instanced: Arc::default(),
            local: Vec::new(),
        };
        self.jobs_of(&d, &snapshots, &flat, &Default::default())
    }

    /// The state of each of `shapes` (`DRAWABLE` or not), found in one walk over them, which
    /// also points out the names defined again (both definitions are drawn) and the
    /// materials used before their definition.
    fn flat_shape_states(
        &mut self,
        shapes: &FlatShapes,
        resolved: &[Option<usize>],
        d: &Definitions,
        first_def: &HashMap<&str, (usize, u32)>,
    ) -> Vec<u8> {
        let mut state = vec![0u8; shapes.len()];
        let mut latest = NameTable::new(shapes.len());
        let mut hashes = Vec::new();
        let mut k = 0;
        for chunk in shapes.chunks() {
            // The names of a chunk are hashed first: the table's slots, far apart in
            // memory, are then looked up in a tight loop whose loads overlap.
            hashes.clear();
            hashes.extend(chunk.iter().map(|s| NameTable::hash(shapes.name(s))));
            for (s, &hash) in chunk.iter().zip(&hashes) {
                let name = shapes.name(s);
                if resolved[shapes.material_of(s)].is_some() && degeneracy(&s.geometry).is_none() {
                    state[k] = DRAWABLE;
                }
                let earlier = latest.insert(hash, name, k, |j| {
                    shapes.get(j).map_or("", |e| shapes.name(e))
                });
                k += 1;
                // Course renderers that keep every shape in a list draw both; nothing here
                // refers to a shape by name, so nothing needs the name to be one shape's.
                if let Some(earlier_line) = earlier.and_then(|j| Some(shapes.get(j)?.line())) {
                    let (loc, width) = shapes.name_place(s);
                    self.warn(
                        At::Place(&loc, width),
                        format!(
                            "shape `{name}` is already defined (line {earlier_line}); both are drawn, and the name refers to this one"
                        ),
                        None,
                    );
                }
                let material = shapes.material_of(s);
                if !shapes.material_defined_before(s)
                    && d.material_index
                        .contains_key(shapes.material_name(material))
                {
                    self.resolve_material(d, first_def, 0, &shapes.material_ref(s));
                }
            }
        }
        state
    }
}

/// The uses of materials no statement defines, as (material, shape name), to be reported
/// with the shapes using them as for shapes read as statements.
fn unknown_material_uses(statements: &[Statement], shapes: &FlatShapes) -> Vec<(NameRef, String)> {
    let defined: FastSet<&str> = statements
        .iter()
        .filter_map(|s| match &s.kind {
            StatementKind::Material(m) => Some(m.name.as_str()),
            _ => None,
        })
        .collect();
    let unknown_ids: Vec<bool> = (0..shapes.material_count())
        .map(|id| !defined.contains(shapes.material_name(id)))
        .collect();
    if unknown_ids.contains(&true) {
        shapes
            .iter()
            .filter(|s| unknown_ids[shapes.material_of(s)])
            .map(|s| (shapes.material_ref(s), shapes.name(s).to_string()))
            .collect()
    } else {
        Vec::new()
    }
}

/// Where each material is first defined, placed after every shape that the reader saw before
/// it (index 0 in `Builder::flat_shape_states`): for "used before its definition".
fn material_first_defs(statements: &[Statement]) -> HashMap<&str, (usize, u32)> {
    let mut first_def: HashMap<&str, (usize, u32)> = HashMap::new();
    for (index, stmt) in statements.iter().enumerate() {
        if let StatementKind::Material(m) = &stmt.kind {
            first_def
                .entry(m.name.as_str())
                .or_insert((index + 1, stmt.loc.line));
        }
    }
    first_def
}

/// The instances of the shapes drawn (by `state`), `count` of them, with their names; each
/// chunk of `shapes` is freed once turned into instances.
fn flat_instances(
    shapes: &mut FlatShapes,
    state: &[u8],
    resolved: &[Option<usize>],
    count: usize,
) -> (Vec<Instance>, Names) {
    let mut instances = Vec::new();
    let mut names = Names::default();
    instances.reserve_exact(count);
    names.reserve(count, shapes.names_len());
    let files: Vec<_> = shapes.files().iter().map(|f| names.file_id(f)).collect();
    let mut k = 0;
    for chunk in shapes.take_chunks() {
        for s in chunk {
            k += 1;
            if state[k - 1] != DRAWABLE {
                continue;
            }
            let material = resolved[shapes.material_of(&s)];
            let (Some(material), Some(&file)) = (material, files.get(shapes.file_of(&s))) else {
                continue;
            };
            let object = names.add_object_in(shapes.name(&s), file, s.line(), s.col());
            instances.push(Instance {
                geometry: placed_geometry(s.geometry),
                material,
                transform: 0,
                object,
                parent: NO_NAME,
            });
        }
    }
    (instances, names)
}

/// A shape's state in `flat_jobs`: its material resolves and it can be drawn.
const DRAWABLE: u8 = 2;

/// The shapes seen so far by name, to find a name defined again: an open-addressing table of
/// 8 bytes a slot (a 32-bit hash tag and the shape's index), about a sixth of a `HashMap`
/// from names to indices. A tag match is confirmed by comparing the names.
struct NameTable {
    slots: Vec<u64>,
    mask: usize,
}

impl NameTable {
    /// A table for `n` names, at most half full.
    fn new(n: usize) -> Self {
        let len = n.saturating_mul(2).next_power_of_two().max(16);
        NameTable {
            slots: vec![0; len],
            mask: len - 1,
        }
    }

    /// The hash of `name` to record it under.
    fn hash(name: &str) -> u64 {
        FastHash::default().hash_one(name)
    }

    /// Records shape `k` (below 2^32 - 1) named `name`, of hash [`NameTable::hash`]; the last shape recorded under the same
    /// name, if any. `name_of` gives the name of a shape recorded before.
    fn insert<'n>(
        &mut self,
        hash: u64,
        name: &str,
        k: usize,
        name_of: impl Fn(usize) -> &'n str,
    ) -> Option<usize> {
        let tag = hash >> 32;
        let entry = (tag << 32) | (k as u64 + 1);
        let mut i = hash as usize & self.mask;
        loop {
            let slot = self.slots[i];
            if slot == 0 {
                self.slots[i] = entry;
                return None;
            }
            if slot >> 32 == tag {
                let j = (slot & 0xffff_ffff) as usize - 1;
                if name_of(j) == name {
                    self.slots[i] = entry;
                    return Some(j);
                }
            }
            i = (i + 1) & self.mask;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::NameTable;

    #[test]
    fn the_name_table_finds_the_last_shape_of_a_name() {
        let names = ["a", "b", "a", "c", "b", "a"];
        let mut t = NameTable::new(names.len());
        let earlier: Vec<Option<usize>> = names
            .iter()
            .enumerate()
            .map(|(k, n)| t.insert(NameTable::hash(n), n, k, |j| names[j]))
            .collect();
        assert_eq!(earlier, [None, None, Some(0), None, Some(1), Some(2)]);
        // A full run of distinct names, more than the table's first guess of slots.
        let many: Vec<String> = (0..5000).map(|i| format!("s{i}")).collect();
        let mut t = NameTable::new(many.len());
        for (k, n) in many.iter().enumerate() {
            assert_eq!(
                t.insert(NameTable::hash(n), n, k, |j| many[j].as_str()),
                None
            );
        }
        let hash = NameTable::hash("s4999");
        assert_eq!(
            t.insert(hash, "s4999", 5000, |j| many[j].as_str()),
            Some(4999)
        );
    }
}
