//! The dialect contract: what a scene file may say and how anim answers it: the statements and
//! variants real users write are read as their authors' renderers read them (with a warning
//! naming the reading), and everything else is refused at its line and column. A test belongs
//! here when its claim is about reading scene text; inputs built to hurt have tests/hostile/.
//!
//! - `diagnostics`: malformed and suspicious input, row by row, with the severity, line and
//!   column each must produce.
//! - `corpus`: every real-world file of the shared corpus loads or is refused with located
//!   errors.
//! - `intent`: material layouts inferred per file, and no silent blank image.
//! - `intent_forms`: forms other renderers accepted, each warned about, an error under
//!   `--strict`, and not blank.

#[path = "../common/mod.rs"]
mod common;

mod corpus;
mod diagnostics;
mod forms_more;
mod include;
mod intent;
mod intent_forms;
