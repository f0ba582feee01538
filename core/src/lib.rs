//! tracelab-core: the scene graph, the MIT 6.837 scene format (reader and writer), geometry,
//! acceleration structures and the progressive CPU ray tracer. No GUI dependencies.
#![deny(unsafe_code)]

pub mod accel;
pub mod format;
pub mod geometry;
pub mod memory;
pub mod render;
pub mod scene;
pub mod simd;
// The tests' data folders (TRACELAB_MESHES_DIR, …), read in one file for every test; the
// unit tests use only some of them.
#[cfg(test)]
#[path = "../tests/common/data.rs"]
#[allow(dead_code)]
mod test_data;

pub use format::obj::{MESH_LOAD_CANCELLED, MeshCache, MeshEvent, MeshObserver};
pub use format::{
    Diagnostic, Diagnostics, ParseOutcome, Severity, SourceFile, load_scene, load_scene_unresolved,
    parse_scene, parse_scene_unresolved, rebase_mesh_paths, resolve_meshes, try_write_scene,
    write_scene,
};
pub use memory::OutOfMemory;
pub use render::{
    CompiledScene, Frame, NormalTransform, ObjectRays, RenderSettings, Sample, SharedFrame, View,
    compile, render_frame,
};
pub use scene::{
    Anchor, Background, Camera, Comments, CsgOp, DEFAULT_MATERIAL_COLOR, Field, Graph, Invalid,
    Light, Material, MaterialKeyword, Mesh, MeshSlot, Node, NodeId, NodeKind, Place, Problem,
    Scene, SceneComments, SolidTexture, TextureKind, TransformOp, check_scene,
};
