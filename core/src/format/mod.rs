//! The MIT 6.837 scene format: lexer, parser (errors as values with file:line:col),
//! writer, and OBJ loading.

mod diagnostic;
mod lexer;
pub mod obj;
mod parser;
mod rebase;
mod token_stream;
mod writer;

pub use diagnostic::{Diagnostic, Diagnostics, Severity, SourceFile, escape_controls};
pub(crate) use parser::is_numberlike;
pub use parser::{MAX_SCENE_BYTES, ParseOutcome, load_scene, parse_scene};
pub use rebase::rebase_mesh_paths;
pub use writer::{try_write_scene, uses_only_course_grammar, write_scene};
