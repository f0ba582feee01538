//! tracelab the application: command line and desktop editor over `tracelab-core`.

pub mod app;
pub mod cli;
pub mod edit;
pub mod io;
pub mod loading;
pub mod render_worker;
pub mod state;
pub mod ui;

/// The scene tracelab opens when started with no file.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/default.txt");
pub const DEFAULT_SCENE_NAME: &str = "default.txt (built in)";
pub mod bench;
