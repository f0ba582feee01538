//! The MIT 6.837 scene format: lexer, parser (errors as values with file:line:col),
//! writer, and OBJ loading (a step of its own after parsing: [`resolve_meshes`]).

mod diagnostic;
mod lexer;
mod load;
pub mod obj;
mod parser;
mod rebase;
mod resolve;
mod token_stream;
mod writer;

pub use diagnostic::{Diagnostic, Diagnostics, Severity, SourceFile, escape_controls};
pub use load::{load_scene, parse_scene};
pub use parser::{
    Located, MAX_SCENE_BYTES, MeshRef, ParseOutcome, load_scene_unresolved, parse_scene_unresolved,
};
pub use rebase::rebase_mesh_paths;
pub use resolve::resolve_meshes;
pub use writer::{
    TooLargeToReadBack, check_reads_back, try_write_scene, uses_only_course_grammar, write_scene,
};
