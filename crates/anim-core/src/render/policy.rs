//! Which structure answers which ray: every threshold that picks a strategy, in one table,
//! and the two decisions made from it once per compiled scene ([`geometry_plan`] when the
//! geometry is built, [`view_plan`] when the view is). Every strategy gives the same answers
//! to the bit; they differ only in cost, and each earns its place by its measurement in
//! BENCHMARKS.md ("The render core"), made by toggling it here.

/// Most bounded primitives a scene may have for every ray to test them all as one leaf, four
/// at a time, instead of walking the hierarchy, and for the eye and the lights to keep
/// direction cells: a room of ten shapes, whose hierarchy puts them in three leaves that most
/// rays inside the room meet anyway.
pub const FLAT_MAX: usize = 16;

/// Fewest bounded primitives for direction cells around the eye and the lights: with one
/// group of four, one test is all a list could save.
pub const CELLS_MIN: usize = 5;

/// Fewest bounded primitives for shadow rays to look their candidates up in image tiles
/// around the lights (the camera's tiles start where the flat leaf ends).
pub const LIGHT_TILES_MIN: usize = 64;

/// Fewest nodes of the hierarchy for camera rays to walk it in packets: over a few nodes the
/// walk costs little, and gathering a packet's answers costs more than it saves.
pub const PACKET_MIN_NODES: usize = 16;

/// Most moving shapes a shadow ray asks one by one whether they block it (past this, asking
/// them costs about what the hierarchy does): where the lights a pixel's first pass saw
/// fully are taken as seen past what holds still.
pub const MOVING_BLOCKS_MAX: usize = 16;

/// Largest share of its pixels a frame of a shot may trace again for the next frame to be
/// traced from it too (`super::shot::Shot::render`): above it, the next is rendered as alone.
/// Where every pixel is traced again, watching the rays costs more than rendering the frame
/// alone, and the frames of a shot pay one plain cost per frame plus their share traced again;
/// this is where the two meet (BENCHMARKS.md, "Animations").
pub const RETRACED_SHARE_MAX: f64 = 0.9;

/// How a geometry's rays meet its primitives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GeometryPlan {
    /// Every bounded primitive is tested as one leaf instead of walking the hierarchy.
    pub flat: bool,
    /// Every primitive is a packed sphere: leaves are tested without asking kinds.
    pub spheres_only: bool,
    /// A shadow ray may ask the moving shapes alone whether they block it
    /// (`RenderScene::moving_shadow`): they are few enough ([`MOVING_BLOCKS_MAX`]), or none.
    pub ask_moving: bool,
}

/// The plan of a geometry of `bounded` primitives with finite bounds and `moving` moving
/// shapes: flat when few, but not with moving shapes, whose bounds span the whole exposure
/// where the hierarchy skips them and a flat leaf would test them.
pub fn geometry_plan(bounded: usize, moving: usize, spheres_only: bool) -> GeometryPlan {
    GeometryPlan {
        flat: bounded > 0 && bounded <= FLAT_MAX && moving == 0,
        spheres_only,
        ask_moving: moving <= MOVING_BLOCKS_MAX,
    }
}

/// Where the candidates of rays from one known point (the eye, a light) are looked up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lookup {
    /// Nowhere: the geometry's own strategy answers.
    None,
    /// Direction cells around the point (`crate::accel::DirectionCells`).
    Cells,
    /// Image tiles seen from the point (`crate::accel::ImageTiles`).
    Tiles,
}

/// How a compiled scene answers the rays whose start it knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewPlan {
    /// Camera rays.
    pub eye: Lookup,
    /// Shadow rays, towards every light.
    pub lights: Lookup,
    /// Camera rays walk the hierarchy in packets.
    pub camera_packets: bool,
}

/// What [`view_plan`] decides from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewFacts {
    /// Bounded primitives of the geometry.
    pub bounded: usize,
    /// Nodes of its hierarchy.
    pub hierarchy_nodes: usize,
    /// Camera rays the render traces at least (`None`: no camera, as in a test of the
    /// geometry alone).
    pub camera_rays: Option<u64>,
    /// Whether something moves during the exposure (a shape, a light or the camera).
    pub motion: bool,
    /// Whether a light moves.
    pub lights_move: bool,
}

/// The view plan of a scene.
///
/// - A scene flat but for what moves, of more than one group of four, keeps direction cells
///   around the eye and the lights (not around a moving light: its shadow rays end where it
///   is at their instant, away from the cells' centre). A moving shape is listed by its
///   bounds over the whole exposure, as the hierarchy bounds it.
/// - A larger scene that holds still, rendered with at least as many camera rays as it has
///   primitives, projects them onto the camera's image and, from [`LIGHT_TILES_MIN`] on,
///   onto an image around each light; with fewer rays, building the tiles costs more than
///   they save.
/// - Camera rays of a still frame walk a hierarchy of [`PACKET_MIN_NODES`] nodes or more in
///   packets (the rays of a block sample different instants in a moving frame).
pub fn view_plan(facts: ViewFacts) -> ViewPlan {
    let n = facts.bounded;
    let cells = (CELLS_MIN..=FLAT_MAX).contains(&n);
    let tiles = !facts.motion && n > FLAT_MAX && facts.camera_rays.is_some_and(|r| n as u64 <= r);
    let eye = match () {
        _ if cells && facts.camera_rays.is_some() => Lookup::Cells,
        _ if tiles => Lookup::Tiles,
        _ => Lookup::None,
    };
    let lights = match () {
        _ if cells && !facts.lights_move => Lookup::Cells,
        _ if tiles && n >= LIGHT_TILES_MIN => Lookup::Tiles,
        _ => Lookup::None,
    };
    ViewPlan {
        eye,
        lights,
        camera_packets: !facts.motion && facts.hierarchy_nodes >= PACKET_MIN_NODES,
    }
}
