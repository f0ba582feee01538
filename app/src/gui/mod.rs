//! The desktop editor (eframe): the app that wires the document, the panels and the render
//! worker together.

pub mod animation_dialog;
pub mod app;
pub mod command;
pub mod drag_speed;
pub mod file_dialog;
pub mod file_watch;
pub mod gizmo;
pub mod grid_view;
pub mod layout;
pub mod lecture;
pub mod light_gizmo;
pub mod loading;
pub mod menu;
pub mod mesh_load;
pub mod native_dialog;
pub mod notifications;
pub mod on_screen;
pub mod overlays;
pub mod panels;
pub mod ray_diagram;
pub mod settings;
pub mod view_menus;
pub mod view_tools;
pub mod widgets;

pub use app::{AppOptions, Pending, TracelabApp, run};
