//! The panels. Each reads the document and returns what it asks for (edits, commands); the
//! app carries those out in one place (`crate::gui::command`).

mod fields;
pub mod inspector;
pub mod loading;
mod phong;
pub mod pixel_inspector;
pub mod ray_panel;
pub mod status;
pub mod tree;
pub mod view_bar;
pub mod view_settings;
pub mod view_textures;
pub mod viewport;
