//! Diagnostics on standard error through `log` + `env_logger`: `RUST_LOG` as usual (off by
//! default, so wgpu and eframe stay quiet), and the two switches the README documents, each
//! turning on one target:
//! - `TRACELAB_LOG_TIMES=1` → `tracelab::times` (edit → first image → full → on screen);
//! - `TRACELAB_LOG_FRAMES=1` → `tracelab::frames` (the UI code's time per frame).

/// Timings of renders and of their arrival on screen.
pub const TIMES: &str = "tracelab::times";
/// The UI code's time per frame.
pub const FRAMES: &str = "tracelab::frames";

/// Installs the logger once; later calls do nothing.
pub fn init() {
    let mut b = env_logger::Builder::new();
    // Core's warnings (an unknown TRACELAB_SIMD, …) are shown unless RUST_LOG says otherwise:
    // never silently ignored.
    b.filter(Some("tracelab_core"), log::LevelFilter::Warn);
    b.parse_env(env_logger::Env::default().default_filter_or("off"));
    let on = |var: &str| std::env::var_os(var).is_some_and(|v| !v.is_empty() && v != "0");
    if on("TRACELAB_LOG_TIMES") {
        b.filter(Some(TIMES), log::LevelFilter::Info);
    }
    if on("TRACELAB_LOG_FRAMES") {
        b.filter(Some(FRAMES), log::LevelFilter::Info);
    }
    // "tracelab: …", as every other message of the program starts; escaped, since a
    // message may quote a path.
    b.format(|buf, record| {
        use std::io::Write as _;
        if record.target().starts_with("tracelab") {
            let text = record.args().to_string();
            writeln!(buf, "tracelab: {}", crate::io::escape_text(&text))
        } else {
            writeln!(
                buf,
                "{}: {}: {}",
                record.target(),
                record.level(),
                record.args()
            )
        }
    });
    let _ = b.try_init();
}
