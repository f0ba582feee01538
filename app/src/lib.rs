//! tracelab the application: command line and desktop editor over `tracelab-core`.
//!
//! Layers, each using only those below it: `cli` (dispatch) → `bench`, `gui` → `document`,
//! `navigation`, `bounds`, `node_label`, `render_worker`, `io`, `exit`. Nothing imports
//! `cli`. The editor (`gui`) is the cargo feature `gui`, on by default; without it the
//! command line builds without eframe, egui, wgpu and winit, so nothing outside `gui` may
//! use them.

pub mod animation;
pub mod bench;
pub mod bounds;
pub mod cli;
pub mod document;
pub mod exit;
#[cfg(feature = "gui")]
pub mod gui;
pub mod io;
pub mod logging;
pub mod navigation;
pub mod node_label;
pub mod render_worker;
pub mod story;
#[cfg(test)]
mod test_support;

/// The scene tracelab opens when started with no file.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/default.txt");
pub const DEFAULT_SCENE_NAME: &str = "default.txt (built in)";
