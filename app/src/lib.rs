//! tracelab the application: command line and desktop editor over `tracelab-core`.
//!
//! Layers, each using only those below it: `cli` (dispatch) → `bench`, `gui` → `document`,
//! `render_worker`, `io`, `exit`. Nothing imports `cli`.

pub mod animation;
pub mod bench;
pub mod cli;
pub mod document;
pub mod exit;
pub mod gui;
pub mod io;
pub mod logging;
pub mod render_worker;
pub mod story;
#[cfg(test)]
mod test_support;

/// The scene tracelab opens when started with no file.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/default.txt");
pub const DEFAULT_SCENE_NAME: &str = "default.txt (built in)";
