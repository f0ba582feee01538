//! The errors that decide how the program ends, raised wherever the command line, the
//! benchmarks or output code find them; any other error is a failure (exit 1). `cli::main`
//! maps them to exit codes.

use tracelab_core::render::check_image_size;

#[derive(Debug, thiserror::Error)]
pub enum Exit {
    /// A usage error (exit 2), printed with a pointer to `--help`.
    #[error("{0}")]
    Usage(String),
    /// A usage error already printed (by clap).
    #[error("usage error")]
    UsagePrinted,
    /// The reader of standard output went away (`| head`): it wanted no more, so stop
    /// quietly with success, as a program killed by SIGPIPE would in a shell pipeline.
    #[error("standard output closed")]
    OutputClosed,
    /// `tracelab diff`: the images were compared and do not match (exit 3; the comparison
    /// itself was printed).
    #[error("the images do not match")]
    Differs,
    /// `tracelab diff`: the verdicts were printed, but a heat map could not be written
    /// (exit 4 when every image matched, 5 when one did not); `message` says why.
    #[error("{message}")]
    HeatMapNotWritten { matched: bool, message: String },
}

/// The size limit of `tracelab_core::render::check_image_size`, as a usage error.
pub fn check_size(width: u32, height: u32) -> anyhow::Result<()> {
    check_image_size(width, height).map_err(|e| usage(e.to_string()))
}

/// A usage error, for `?` and `Err(..)` in functions returning `anyhow::Result`.
pub fn usage(message: impl Into<String>) -> anyhow::Error {
    Exit::Usage(message.into()).into()
}
