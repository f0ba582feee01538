//! Standard output and error for the command line: every write to standard output checked
//! (closed, full, broken pipe), and text that carries what a user or a file chose (paths,
//! node names, `obj_file` names) escaped so that it cannot drive the terminal.

use std::borrow::Cow;
use std::io::Write;

use tracelab_core::format::escape_controls;

use crate::exit::Exit;

/// Writes bytes to standard output as they are (`fmt`'s scene text, JSON), checking the
/// write and the flush: a reader that closed the pipe (`| head`) wanted no more, which ends
/// the run quietly ([`Exit::OutputClosed`]); a full or failing standard output is an error.
/// A standard output that looks closed (see [`closed_at_start`]) gets a warning, not an
/// error: it cannot be told from /dev/null opened for reading and writing, which is what
/// Python's `subprocess.DEVNULL` gives a grading script that only wants the exit code.
pub fn write_stdout(bytes: &[u8]) -> anyhow::Result<()> {
    static WARNED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
    if closed_at_start() && !WARNED.swap(true, std::sync::atomic::Ordering::Relaxed) {
        write_stderr_text(
            "tracelab: warning: standard output is closed (or is /dev/null opened for reading \
             and writing): what this command prints is lost\n",
        );
    }
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(Exit::OutputClosed.into()),
        Err(e) => Err(anyhow::anyhow!("standard output: cannot write: {e}")),
    }
}

/// Writes a report for people (`inspect`, `diff`) with [`escape_text`] applied.
pub fn write_stdout_text(text: &str) -> anyhow::Result<()> {
    write_stdout(escape_text(text).as_bytes())
}

/// [`write_stdout_text`] for a summary followed by a verdict (`diff`): a reader gone
/// (`| head`) drops the text, not the verdict, which still sets the exit code (and a side
/// output's failure still reports itself); a full or failing standard output is an error.
pub fn write_summary_text(text: &str) -> anyhow::Result<()> {
    match write_stdout_text(text) {
        Err(e) if matches!(e.downcast_ref::<Exit>(), Some(Exit::OutputClosed)) => Ok(()),
        other => other,
    }
}

/// Writes a message to standard error with [`escape_text`] applied; with standard error
/// closed or full there is no one left to tell, so a failure is ignored.
pub fn write_stderr_text(text: &str) {
    let _ = std::io::stderr()
        .lock()
        .write_all(escape_text(text).as_bytes());
}

/// Text made safe for a terminal line by line: core's [`escape_controls`] (control
/// characters and bidirectional overrides as `\x1b`, `\u{202e}`), keeping the line breaks
/// that separate the lines. Already escaped text comes back unchanged.
pub fn escape_text(text: &str) -> Cow<'_, str> {
    if text
        .split('\n')
        .all(|l| matches!(escape_controls(l), Cow::Borrowed(_)))
    {
        return Cow::Borrowed(text);
    }
    Cow::Owned(
        text.split('\n')
            .map(escape_controls)
            .collect::<Vec<_>>()
            .join("\n"),
    )
}

/// serde_json's text with what it leaves raw inside strings (DEL, the C1 controls such as
/// the one-byte CSI U+009B, bidirectional overrides) written as `\uXXXX` escapes: the same
/// JSON to a parser, harmless on a terminal. Outside strings JSON has only ASCII
/// punctuation, digits, letters and spaces, so every such character is inside a string.
pub fn escape_json(json: String) -> String {
    // Pretty JSON's own line breaks and indents are ASCII: only DEL and non-ASCII are asked.
    let unsafe_char = |c: char| {
        let mut buf = [0u8; 4];
        (c == '\u{7f}' || !c.is_ascii())
            && matches!(escape_controls(c.encode_utf8(&mut buf)), Cow::Owned(_))
    };
    if !json.chars().any(unsafe_char) {
        return json;
    }
    let mut out = String::with_capacity(json.len() + 16);
    for c in json.chars() {
        if unsafe_char(c) {
            // Every character escape_controls rewrites is in the Basic Multilingual Plane.
            out.push_str(&format!("\\u{:04x}", c as u32));
        } else {
            out.push(c);
        }
    }
    out
}

/// Whether standard output was closed when the program started (`tracelab fmt x >&-`).
/// Rust's runtime opens /dev/null, read-write, in place of a closed standard stream, so
/// writes would "succeed" into nothing; a shell's `>/dev/null` opens it write-only. So
/// /dev/null open for reading and writing on descriptor 1 is taken as "closed".
#[cfg(target_os = "linux")]
fn closed_at_start() -> bool {
    use std::os::fd::AsFd;
    let stdout = std::io::stdout();
    let fd = stdout.as_fd();
    let Ok(stat) = rustix::fs::fstat(fd) else {
        return true; // not open at all
    };
    let is_dev_null = rustix::fs::FileType::from_raw_mode(stat.st_mode)
        == rustix::fs::FileType::CharacterDevice
        && (
            rustix::fs::major(stat.st_rdev),
            rustix::fs::minor(stat.st_rdev),
        ) == (1, 3);
    is_dev_null
        && rustix::fs::fcntl_getfl(fd)
            .is_ok_and(|f| f & rustix::fs::OFlags::RWMODE == rustix::fs::OFlags::RDWR)
}

#[cfg(not(target_os = "linux"))]
fn closed_at_start() -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escape_text_keeps_line_breaks_and_escapes_the_rest() {
        assert_eq!(escape_text("a\nb ⁻¹ °\n"), "a\nb ⁻¹ °\n");
        assert!(matches!(escape_text("a\nb"), Cow::Borrowed(_)));
        assert_eq!(
            escape_text("x\u{1b}[2J\ny\r\u{7}\u{202e}z\n"),
            "x\\x1b[2J\ny\\x0d\\x07\\u{202e}z\n"
        );
        let once = escape_text("\u{1b}]0;t\u{7}").into_owned();
        assert_eq!(escape_text(&once), once);
    }

    #[test]
    fn escape_json_keeps_the_value_and_leaves_nothing_raw_for_a_terminal() {
        let name = "m\u{1b}[31m\r\u{7}\u{7f}\u{9b}2J\u{202e}é✓.obj";
        let json =
            serde_json::to_string_pretty(&serde_json::json!({ "label": name })).expect("json");
        let safe = escape_json(json);
        assert!(
            !safe
                .chars()
                .any(|c| c.is_control() && c != '\n' || c == '\u{202e}'),
            "{safe:?}"
        );
        assert!(safe.contains("é✓"), "other text is kept: {safe}");
        let back: serde_json::Value = serde_json::from_str(&safe).expect("valid JSON");
        assert_eq!(back["label"], name);
    }
}
