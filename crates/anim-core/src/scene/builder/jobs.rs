//! One render job per render statement: the camera it names and the scene as it stands
//! there, with the composite tree flattened into instances.

use super::definitions::{Definitions, Object, ObjectKind};
use super::motion::{job_motion, moves_objects, MotionLines};
use super::transforms::{finite_transform, Snapshot, Space};
use super::{At, Builder, Building, Plan};
use crate::diag::Diagnostic;
use crate::diag::Severity;
use crate::limits::MAX_WALK;
use crate::limits::{self, DEFAULT_IMAGE_SIZE, MAX_NESTING};
use crate::math::Transform;
use crate::scene::{
    Camera, Geometry, Instance, Instanced, Lens, Light, Names, RenderJob, Scene, Spot, NO_NAME,
};
use crate::sdf::ast::{CameraDef, NameRef, Statement, StatementKind};
use crate::sdf::default_output;
use crate::util::human_bytes;
use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::Arc;

impl Builder<'_> {
    // ----- jobs --------------------------------------------------------------------------

    pub(super) fn jobs<'s>(
        &mut self,
        statements: &'s [Statement],
        d: &Definitions<'s>,
    ) -> Vec<RenderJob> {
        let snapshots = self.snapshots(statements, d);
        let lines = self.motion_lines(statements, d);
        // The composite tree is the same for every job; only the transforms differ. It is
        // flattened once, into instances every job shares: each place where an object that
        // some transform statement moves is listed gets its own transform slot, the rest share
        // their parent's, and each job fills the slots from its own transforms.
        let mut moved = vec![false; d.objects.len()];
        for (_, snapshot) in &snapshots {
            for (space, name) in snapshot.keys() {
                if let (Space::Object, Some(&i)) = (space, d.object_index.get(name)) {
                    moved[i] = true;
                }
            }
        }
        // A moving object gets its own slot, which its motion keys replace per instant.
        for (i, o) in d.objects.iter().enumerate() {
            moved[i] |= lines.moves_object(o.name);
        }
        let roots = roots(d);
        // Motion inside a prototype would move every use of it: a scene in which shapes or
        // composites move is flattened without prototypes (docs/scene-language.md §10).
        let plan = if moves_objects(&lines, d) {
            Plan::default()
        } else {
            self.instancing_plan(d, &roots)
        };
        let shapes = {
            let expansion = if plan.is_active() {
                self.stored_expansion(d, &roots, &moved, &plan)
            } else {
                expansion(d, &roots, &moved)
            };
            let tree = Tree {
                roots: &roots,
                expansion: &expansion,
            };
            self.expansion_fits(d, &tree, snapshots.len() as u64)
        };
        // The counts are freed before the instances are made.
        let flat = self.flatten_tree(d, &roots, shapes, &moved, plan);
        self.jobs_of(d, &snapshots, &flat, &lines)
    }

    /// One job per render statement (or the default one), each placing the shared instances
    /// of `flat` by its own transforms.
    pub(super) fn jobs_of(
        &mut self,
        d: &Definitions,
        snapshots: &[(Option<&Statement>, Snapshot)],
        flat: &Flat,
        lines: &MotionLines,
    ) -> Vec<RenderJob> {
        let mut jobs = Vec::new();
        for (render, snapshot) in snapshots {
            let job = match render {
                Some(stmt) => {
                    let StatementKind::Render(r) = &stmt.kind else {
                        continue;
                    };
                    let Some(camera) = self.render_camera(d, &r.camera, snapshot) else {
                        continue;
                    };
                    RenderJob {
                        scene: self.scene(d, flat, snapshot, lines, &camera),
                        camera,
                        output: PathBuf::from(&r.output),
                        width: r.width,
                        height: r.height,
                        samples: r.samples,
                        loc: Some(stmt.loc.clone()),
                    }
                }
                None => {
                    if self.omissions.render_lines > 0
                        || (self.omissions.cameras_rejected && d.cameras.is_empty())
                    {
                        // The render line or the camera was rejected, with an error: no stand-in.
                        continue;
                    }
                    let camera = match d.cameras.first() {
                        Some(c) => place_camera(c, d, snapshot),
                        None => Camera::default_with_fov("default", limits::DEFAULT_FOV_DEG),
                    };
                    let output = default_output(self.path);
                    let mut w = Diagnostic::file_error(
                        self.path,
                        format!(
                            "no render statement: camera `{}` is rendered to `{output}` at {}×{}",
                            camera.name, DEFAULT_IMAGE_SIZE.0, DEFAULT_IMAGE_SIZE.1
                        ),
                    )
                    .with_help("add e.g. `render <camera> image.png 800 600`");
                    w.severity = Severity::Warning;
                    self.push(w);
                    RenderJob {
                        scene: self.scene(d, flat, snapshot, lines, &camera),
                        camera,
                        output: PathBuf::from(output),
                        width: DEFAULT_IMAGE_SIZE.0,
                        height: DEFAULT_IMAGE_SIZE.1,
                        samples: None,
                        loc: None,
                    }
                }
            };
            jobs.push(job);
        }
        jobs
    }

    pub(super) fn render_camera(
        &mut self,
        d: &Definitions,
        name: &NameRef,
        snapshot: &Snapshot,
    ) -> Option<Camera> {
        match d.camera_index.get(name.name.as_str()) {
            Some(&i) => Some(place_camera(d.cameras[i], d, snapshot)),
            None => {
                if !self.skipped(&name.name) {
                    let help = self
                        .name_help(&name.name, d.camera_index.keys().copied())
                        .or_else(|| {
                            d.cameras
                                .first()
                                .map(|c| format!("the file defines camera `{}`", c.name))
                        });
                    self.at_ref(
                        Severity::Error,
                        name,
                        format!("unknown camera `{}`", name.name),
                        help,
                    );
                }
                None
            }
        }
    }

    /// The scene of one job: the shared instances, placed by this job's transforms.
    fn scene(
        &mut self,
        d: &Definitions,
        flat: &Flat,
        snapshot: &Snapshot,
        lines: &MotionLines,
        camera: &Camera,
    ) -> Scene {
        let mut transforms = Vec::with_capacity(flat.slots.len() + 1);
        transforms.push(Transform::IDENTITY);
        for &(parent, i) in &flat.slots {
            let object = &d.objects[i];
            let own = snapshot
                .get(&(Space::Object, object.name))
                .copied()
                .unwrap_or_default();
            let world = transforms[parent as usize].then_after(&own);
            if finite_transform(&world) {
                transforms.push(world);
                continue;
            }
            if self.reported_composites.insert(object.name.to_string()) {
                self.error(
                    At::Name(object.statement),
                    format!(
                        "the transforms above `{}` multiply out beyond floating-point range",
                        object.name
                    ),
                    Some("use scale factors nearer to 1".to_string()),
                );
            }
            // The file is refused; the slot keeps a usable value meanwhile.
            transforms.push(Transform::IDENTITY);
        }
        let lights = d
            .lights
            .iter()
            .map(|l| {
                let t = snapshot
                    .get(&(Space::Light, l.name.as_str()))
                    .copied()
                    .unwrap_or_default();
                // The target is a point the light's transforms carry with it; the radius and
                // the angles are as written.
                Light {
                    name: l.name.clone(),
                    position: t.point(l.position),
                    intensity: l.color * l.brightness,
                    radius: l.radius,
                    spot: l.spot.map(|s| Spot {
                        target: t.point(s.target),
                        inner_deg: s.inner_deg,
                        outer_deg: s.outer_deg,
                    }),
                }
            })
            .collect::<Vec<Light>>();
        let motion = job_motion(
            d,
            (&flat.instances, &flat.slots),
            snapshot,
            lines,
            &transforms,
            &lights,
            Some(camera),
        );
        let own = |i: usize| snapshot.get(&(Space::Object, d.objects[i].name));
        Scene {
            materials: d.materials.clone(),
            instances: flat.instances.clone(),
            transforms,
            names: flat.names.clone(),
            lights,
            ambient: d.ambient,
            background: d.background,
            instanced: flat.instanced.clone(),
            local_transforms: flat
                .local
                .iter()
                .map(|&i| own(i).copied().unwrap_or_default())
                .collect(),
            motion,
            ..Scene::default()
        }
    }

    /// The composite tree below `roots` flattened into instances: `shapes` of them, or none
    /// when the tree does not fit the memory budget (reported).
    fn flatten_tree(
        &mut self,
        d: &Definitions,
        roots: &[usize],
        shapes: Option<u64>,
        moved: &[bool],
        plan: Plan,
    ) -> Flat {
        let mut flat = Flatten {
            instances: Vec::new(),
            slots: Vec::new(),
            names: Names::default(),
            name_ids: vec![NO_NAME; d.objects.len()],
            inst: Building::new(plan, d.objects.len()),
        };
        if let Some(shapes) = shapes {
            flat.instances
                .reserve_exact(usize::try_from(shapes).unwrap_or(0));
            let mut stack = Vec::new();
            let walked = Walked { defs: d, moved };
            for &root in roots {
                self.flatten(walked, root, 0, NO_NAME, &mut stack, &mut flat);
            }
        }
        flat.instances.shrink_to_fit();
        let (instanced, local) = flat.inst.finish();
        Flat {
            instances: Arc::new(flat.instances),
            slots: flat.slots,
            names: Arc::new(flat.names),
            instanced,
            local,
        }
    }

    /// Appends the instances below object `i`, listed in transform slot `slot` under path
    /// node `path`. `stack` holds the composites being expanded, to stop at cycles.
    pub(super) fn flatten<'s>(
        &mut self,
        walked: Walked<'_, 's>,
        i: usize,
        slot: u32,
        path: u32,
        stack: &mut Vec<&'s str>,
        out: &mut Flatten,
    ) {
        let Walked { defs: d, moved } = walked;
        if self.too_many_reported {
            return; // the scene is refused anyway; do not walk the rest of a huge tree
        }
        let object = &d.objects[i];
        let name = object.name;
        let slot = if moved[i] {
            out.slots.push((slot, i));
            out.slots.len() as u32
        } else {
            slot
        };
        match &object.kind {
            ObjectKind::Shape { geometry, material } => {
                let Some(material) = *material else {
                    return;
                };
                if limits::scene_memory(out.instances.len() as u64 + 1) > self.opts.max_memory {
                    // Counted before flattening, the tree fits; only a cycle (reported when
                    // it is met) can make the walk go on past the count.
                    self.too_many_reported = true;
                    self.error(
                        At::Name(object.statement),
                        format!(
                            "the composite tree expands to more shapes than the {} allowed can hold",
                            human_bytes(self.opts.max_memory)
                        ),
                        Some(format!("{DOUBLING}; {RAISE}")),
                    );
                    return;
                }
                let object = out.name_id(i, object);
                out.instances.push(Instance {
                    geometry: placed_geometry((*geometry).clone()),
                    material,
                    transform: slot,
                    object,
                    parent: path,
                });
                out.inst.leaf();
            }
            ObjectKind::Composite { children } => {
                if let Some(pos) = stack.iter().position(|&s| s == name) {
                    if self.reported_composites.insert(name.to_string()) {
                        let mut cycle: Vec<&str> = stack[pos..].to_vec();
                        cycle.push(name);
                        self.error(
                            At::Name(object.statement),
                            format!("composite `{name}` contains itself ({})", cycle.join(" → ")),
                            None,
                        );
                    }
                    return;
                }
                if stack.len() >= MAX_NESTING {
                    if self.reported_composites.insert(name.to_string()) {
                        self.error(
                            At::Name(object.statement),
                            format!("composites are nested more than {MAX_NESTING} deep"),
                            None,
                        );
                    }
                    return;
                }
                let id = out.name_id(i, object);
                let node = out.names.add_path(path, id);
                if self.use_prototype(walked, i, slot, node, stack, out) {
                    return;
                }
                stack.push(name);
                for &child in children {
                    if let Some(&c) = d.object_index.get(child) {
                        self.flatten(walked, c, slot, node, stack, out);
                    }
                }
                stack.pop();
            }
        }
    }
}

/// A shape's geometry as an instance holds it: the parser makes radii positive, statements
/// made by a program may not.
pub(super) fn placed_geometry(mut geometry: Geometry) -> Geometry {
    if let Some(radius) = geometry.radius_mut() {
        *radius = limits::fixed_radius(*radius);
    }
    geometry
}

/// The composite tree flattened, as the jobs of a file share it.
pub(super) struct Flat {
    pub(super) instances: Arc<Vec<Instance>>,
    /// Transform slot `k` (from 1; slot 0 is the top of the tree) is `slots[k - 1]`: the slot
    /// it is listed in, and the object whose own transform it adds.
    pub(super) slots: Vec<(u32, usize)>,
    pub(super) names: Arc<Names>,
    /// The composites kept once, and the object of each of their transform slots.
    pub(super) instanced: Arc<Instanced>,
    pub(super) local: Vec<usize>,
}

/// A [`Flat`] being made.
pub(super) struct Flatten {
    pub(super) instances: Vec<Instance>,
    pub(super) slots: Vec<(u32, usize)>,
    names: Names,
    /// Object index → its id in `names`, once recorded.
    name_ids: Vec<u32>,
    pub(super) inst: Building,
}

impl Flatten {
    /// The id in `names` of object `i`, recorded the first time it is asked for.
    fn name_id(&mut self, i: usize, object: &Object) -> u32 {
        if self.name_ids[i] == NO_NAME {
            self.name_ids[i] = self.names.add_object(object.name, &object.statement.loc);
        }
        self.name_ids[i]
    }
}

/// What the flattening walks: the definitions, and per object whether a `motion` line moves
/// it (then it gets a transform slot of its own).
#[derive(Clone, Copy)]
pub(super) struct Walked<'a, 's> {
    pub defs: &'a Definitions<'s>,
    pub moved: &'a [bool],
}

/// The objects a scene is drawn from, and what each expands to.
pub(super) struct Tree<'t> {
    roots: &'t [usize],
    expansion: &'t [Expansion],
}

/// What the tree below one object expands to when flattened.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Expansion {
    /// Instances made (shapes with a material).
    pub(super) shapes: u64,
    /// Objects visited on the way, shapes and composites (composites holding nothing cost
    /// walking time too).
    pub(super) nodes: u64,
    /// Transform slots made on the way (visits of objects a transform statement moves).
    pub(super) slots: u64,
}

/// The largest part of a tree, where a tree too large is reported.
pub(super) struct Largest<'a> {
    pub(super) name: &'a str,
    pub(super) composite: bool,
    pub(super) at: At<'a>,
}

/// The roots of the composite tree, in definition order: the composite `root` if there is
/// one, else every object no composite lists.
fn roots(d: &Definitions) -> Vec<usize> {
    if let Some(&i) = d.object_index.get("root") {
        if matches!(d.objects[i].kind, ObjectKind::Composite { .. }) {
            return vec![i];
        }
    }
    let contained: HashSet<&str> = d
        .object_index
        .values()
        .filter_map(|&i| match &d.objects[i].kind {
            ObjectKind::Composite { children } => Some(children.iter().copied()),
            ObjectKind::Shape { .. } => None,
        })
        .flatten()
        .collect();
    let mut roots: Vec<usize> = d
        .object_index
        .iter()
        .filter(|(name, _)| !contained.contains(*name))
        .map(|(_, &i)| i)
        .collect();
    // Shapes whose name a later shape took are drawn where that name would be.
    roots.extend(
        d.shadowed
            .values()
            .filter(|&&i| !contained.contains(d.objects[i].name)),
    );
    roots.sort_unstable(); // definition order
    roots
}

/// What each object expands to, by dynamic programming over the composite DAG (each object
/// computed once from its children's counts): a chain of composites that each list the next
/// twice doubles at every level, and must be refused from its counts, not by walking it.
/// Counts saturate; a child that closes a cycle counts nothing (`flatten` reports the cycle).
/// The walk is iterative, as a chain of composites can be longer than the stack is deep.
fn expansion(d: &Definitions, roots: &[usize], moved: &[bool]) -> Vec<Expansion> {
    const NEW: u8 = 0;
    const OPEN: u8 = 1;
    const DONE: u8 = 2;
    let n = d.objects.len();
    let mut memo = vec![Expansion::default(); n];
    let mut state = vec![NEW; n];
    let child_index = |name: &str| d.object_index.get(name).copied().filter(|&i| i < n);
    for &root in roots {
        if state[root] != NEW {
            continue;
        }
        state[root] = OPEN;
        // (object, index of the next child to visit)
        let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
        while let Some(top) = stack.last_mut() {
            let (i, next) = *top;
            let children: &[&str] = match &d.objects[i].kind {
                ObjectKind::Shape { material, .. } => {
                    memo[i] = Expansion {
                        shapes: u64::from(material.is_some()),
                        nodes: 1,
                        slots: u64::from(moved[i]),
                    };
                    state[i] = DONE;
                    stack.pop();
                    continue;
                }
                ObjectKind::Composite { children } => children,
            };
            if let Some(child) = children.get(next) {
                top.1 += 1;
                if let Some(c) = child_index(child) {
                    if state[c] == NEW {
                        state[c] = OPEN;
                        stack.push((c, 0));
                    }
                }
                continue;
            }
            let mut total = Expansion {
                shapes: 0,
                nodes: 1,
                slots: u64::from(moved[i]),
            };
            for c in children.iter().filter_map(|c| child_index(c)) {
                if state[c] == DONE {
                    total.shapes = total.shapes.saturating_add(memo[c].shapes);
                    total.nodes = total.nodes.saturating_add(memo[c].nodes);
                    total.slots = total.slots.saturating_add(memo[c].slots);
                }
            }
            memo[i] = total;
            state[i] = DONE;
            stack.pop();
        }
    }
    memo
}

impl Builder<'_> {
    /// The shapes the tree expands to, when they fit in the memory budget (`--max-memory`)
    /// together with the transforms of the file's `jobs` jobs, and the tree has at most
    /// [`MAX_WALK`] objects that make no shape. Otherwise reports why, once per file, with
    /// the memory the scene would need.
    fn expansion_fits(&mut self, d: &Definitions, tree: &Tree, jobs: u64) -> Option<u64> {
        if self.too_many_reported {
            return None; // the scene is refused anyway
        }
        let mut shapes: u64 = 0;
        let mut nodes: u64 = 0;
        let mut slots: u64 = 0;
        let mut largest: Option<(u64, usize)> = None;
        for &root in tree.roots {
            let e = tree.expansion[root];
            shapes = shapes.saturating_add(e.shapes);
            nodes = nodes.saturating_add(e.nodes);
            slots = slots.saturating_add(e.slots);
            if largest.is_none_or(|(n, _)| e.nodes > n) {
                largest = Some((e.nodes, root));
            }
        }
        let Some((_, largest)) = largest else {
            return Some(0);
        };
        let object = &d.objects[largest];
        let largest = Largest {
            name: object.name,
            composite: matches!(object.kind, ObjectKind::Composite { .. }),
            at: At::Name(object.statement),
        };
        self.fits(
            Expansion {
                shapes,
                nodes,
                slots,
            },
            &largest,
            jobs,
        )
    }

    /// The shapes of a scene whose tree expands to `total`, when they fit in the memory
    /// budget together with the transforms of the file's `jobs` jobs and the tree has at most
    /// [`MAX_WALK`] objects that make no shape; else reports why at `largest`.
    pub(super) fn fits(&mut self, total: Expansion, largest: &Largest, jobs: u64) -> Option<u64> {
        let Expansion {
            shapes,
            nodes,
            slots,
        } = total;
        let composite = largest.composite;
        let count = |n: u64| {
            if n == u64::MAX {
                "more than 10^19".to_string()
            } else {
                n.to_string()
            }
        };
        let budget = self.opts.max_memory;
        let needed = limits::scene_memory(shapes);
        // Each job holds its own transform for every slot.
        let transform_bytes = std::mem::size_of::<Transform>() as u64;
        let all_jobs =
            needed.saturating_add(jobs.saturating_mul(slots).saturating_mul(transform_bytes));
        let problem = if needed > budget {
            Some(if composite {
                (
                    format!(
                        "the composite tree expands to {} shapes, which need about {} of memory, more than the {} allowed (`{}` is the largest part)",
                        count(shapes),
                        human_bytes(needed),
                        human_bytes(budget),
                        largest.name
                    ),
                    format!("{DOUBLING}; {RAISE}"),
                )
            } else {
                (
                    format!(
                        "the scene's {} shapes need about {} of memory, more than the {} allowed",
                        count(shapes),
                        human_bytes(needed),
                        human_bytes(budget)
                    ),
                    RAISE.to_string(),
                )
            })
        } else if nodes.saturating_sub(shapes) > MAX_WALK {
            Some((
                format!(
                    "the composite tree expands to {} composites and shapes, more than the {MAX_WALK} that are walked (`{}` is the largest part)",
                    count(nodes),
                    largest.name
                ),
                DOUBLING.to_string(),
            ))
        } else if all_jobs > budget {
            Some((
                format!(
                    "the file's render statements together need about {} of memory for their shapes and transforms, more than the {} allowed",
                    human_bytes(all_jobs),
                    human_bytes(budget)
                ),
                format!("write one file per frame (as `anim generate` does) instead of many render lines; {RAISE}"),
            ))
        } else {
            None
        };
        match problem {
            Some((message, help)) => {
                self.too_many_reported = true;
                self.error(largest.at, message, Some(help));
                None
            }
            None => Some(shapes),
        }
    }
}

/// Why a small file can expand to a huge scene.
const DOUBLING: &str =
    "a composite listing another twice, level after level, doubles the scene each time";

/// How to allow a bigger scene.
const RAISE: &str = limits::RAISE_MEMORY;

/// A camera definition with its transform applied (the eye as a point, dir and up as
/// vectors) and its lens, if the definitions `d` give it one of some aperture. The lens is
/// in scene units as written: a transform places the camera, not its optics.
pub(super) fn place_camera(c: &CameraDef, d: &Definitions, snapshot: &Snapshot) -> Camera {
    let t = snapshot
        .get(&(Space::Camera, c.name.as_str()))
        .copied()
        .unwrap_or_default();
    let lens = d.lenses.get(c.name.as_str()).filter(|l| l.aperture > 0.0);
    Camera {
        name: c.name.clone(),
        fov_x_deg: c.fov_x_deg,
        eye: t.point(c.eye),
        dir: t.vector(c.dir),
        up: t.vector(c.up),
        lens: lens.map(|l| Lens {
            aperture: l.aperture,
            focus: l.focus,
        }),
    }
}
