//! Errors and warnings with locations. Spans are byte offsets; line and column (1-based,
//! columns counted in characters) are computed once, for display.

use std::borrow::Cow;
use std::cell::Cell;
use std::fmt;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    Error,
    Warning,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    pub severity: Severity,
    pub file: String,
    /// 1-based; 0 when the message concerns the whole file (e.g. it cannot be read).
    pub line: u32,
    pub col: u32,
    pub message: String,
}

/// Text from a file or a path made safe to print: control characters (ESC, vertical tab, …),
/// bidirectional overrides and invisible characters (a byte-order mark, zero-width spaces)
/// are written as escapes, so a message cannot drive the terminal, reorder what it shows, or
/// quote a word whose fault cannot be seen.
pub fn escape_controls(s: &str) -> Cow<'_, str> {
    let unsafe_char = |c: char| {
        c.is_control()
            || matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
            || matches!(c, '\u{feff}' | '\u{200b}'..='\u{200d}' | '\u{2060}'..='\u{2064}')
    };
    if !s.chars().any(unsafe_char) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        match c {
            _ if !unsafe_char(c) => out.push(c),
            _ if (c as u32) < 0x80 => out.push_str(&format!("\\x{:02x}", c as u32)),
            _ => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
        }
    }
    Cow::Owned(out)
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sev = match self.severity {
            Severity::Error => "",
            Severity::Warning => "warning: ",
        };
        let (file, message) = (escape_controls(&self.file), escape_controls(&self.message));
        if self.line == 0 {
            write!(f, "{file}: {sev}{message}")
        } else {
            write!(f, "{file}:{}:{}: {sev}{message}", self.line, self.col)
        }
    }
}

/// Errors and warnings from one read of a file, in the order found.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Diagnostics(pub Vec<Diagnostic>);

impl Diagnostics {
    pub fn has_errors(&self) -> bool {
        self.0.iter().any(|d| d.severity == Severity::Error)
    }
    pub fn errors(&self) -> impl Iterator<Item = &Diagnostic> {
        self.0.iter().filter(|d| d.severity == Severity::Error)
    }
    pub fn warnings(&self) -> impl Iterator<Item = &Diagnostic> {
        self.0.iter().filter(|d| d.severity == Severity::Warning)
    }
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for d in &self.0 {
            writeln!(f, "{d}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostics {}

/// A file's name and text, for turning byte offsets into line:column.
pub struct SourceFile<'a> {
    pub name: &'a str,
    pub text: &'a str,
    /// Byte offsets where lines start, built on the first lookup (a file without errors
    /// never pays for it) at 4 bytes a line, exactly sized: a file of newlines would
    /// otherwise cost 24 bytes per byte of text.
    line_starts: std::cell::OnceCell<Vec<u32>>,
    /// The last offset looked up, as (line index, offset, column): the parser reports in
    /// file order, so counting characters on from there keeps many errors on one long line
    /// linear instead of quadratic.
    cursor: Cell<(usize, usize, u32)>,
}

impl<'a> SourceFile<'a> {
    pub fn new(name: &'a str, text: &'a str) -> Self {
        SourceFile {
            name,
            text,
            line_starts: std::cell::OnceCell::new(),
            cursor: Cell::new((0, 0, 0)),
        }
    }

    fn line_starts(&self) -> &[u32] {
        self.line_starts.get_or_init(|| {
            // Offsets past 4 GiB (never a scene file: those are capped far below) are left
            // out, so such lines count as part of the last line listed.
            let newline =
                |(i, &b): (usize, &u8)| (b == b'\n').then(|| u32::try_from(i + 1).ok()).flatten();
            let n = self
                .text
                .as_bytes()
                .iter()
                .enumerate()
                .filter_map(newline)
                .count();
            let mut v = Vec::with_capacity(n + 1);
            v.push(0);
            v.extend(self.text.as_bytes().iter().enumerate().filter_map(newline));
            v
        })
    }

    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (u32, u32) {
        let offset = offset.min(self.text.len());
        let starts = self.line_starts();
        let line = starts
            .partition_point(|&s| s as usize <= offset)
            .saturating_sub(1);
        let (c_line, c_off, c_col) = self.cursor.get();
        let (from, base) = if c_line == line && c_off <= offset {
            (c_off, c_col)
        } else {
            (starts.get(line).map_or(0, |&s| s as usize), 0)
        };
        let counted = self
            .text
            .get(from..offset)
            .map_or(offset - from, |s| s.chars().count());
        let col = base.saturating_add(u32::try_from(counted).unwrap_or(u32::MAX));
        self.cursor.set((line, offset, col));
        (
            u32::try_from(line + 1).unwrap_or(u32::MAX),
            col.saturating_add(1),
        )
    }

    pub fn diagnostic(
        &self,
        severity: Severity,
        offset: usize,
        message: impl Into<String>,
    ) -> Diagnostic {
        let (line, col) = self.line_col(offset);
        let message = message.into();
        let message = match escape_controls(&message) {
            Cow::Borrowed(_) => message,
            Cow::Owned(escaped) => escaped,
        };
        Diagnostic {
            severity,
            file: self.name.to_string(),
            line,
            col,
            message,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_counts_from_one_and_in_characters() {
        let s = SourceFile::new("f", "ab\nçd x\n");
        assert_eq!(s.line_col(0), (1, 1));
        assert_eq!(s.line_col(3), (2, 1));
        // 'ç' is two bytes but one column.
        assert_eq!(s.line_col(7), (2, 4));
    }

    #[test]
    fn control_characters_are_escaped_and_other_text_kept() {
        assert_eq!(escape_controls("plain é ✓"), "plain é ✓");
        assert_eq!(
            escape_controls("a\u{1b}[31mb\u{b}c\u{7f}\u{202e}d\u{85}"),
            "a\\x1b[31mb\\x0bc\\x7f\\u{202e}d\\u{85}"
        );
        // Invisible characters too: a BOM inside a file, zero-width spaces.
        assert_eq!(
            escape_controls("\u{feff}Group Sph\u{200b}ere"),
            "\\u{feff}Group Sph\\u{200b}ere"
        );
        // Escaping twice changes nothing more.
        let once = escape_controls("\u{1b}x").into_owned();
        assert_eq!(escape_controls(&once), once);
    }

    #[test]
    fn lookups_in_any_order_agree_with_counting_from_the_line_start() {
        let text = "aé b\nçç ç\n\nxyz";
        let s = SourceFile::new("f", text);
        let offsets: Vec<usize> = (0..=text.len())
            .filter(|&i| text.is_char_boundary(i))
            .collect();
        let expected: Vec<(u32, u32)> = offsets
            .iter()
            .map(|&o| {
                let before = &text[..o];
                let line = before.matches('\n').count() as u32 + 1;
                let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) as u32 + 1;
                (line, col)
            })
            .collect();
        // Forwards (the cursor is reused), backwards, and jumping about.
        let forwards: Vec<_> = offsets.iter().map(|&o| s.line_col(o)).collect();
        assert_eq!(forwards, expected);
        for (k, &o) in offsets.iter().enumerate().rev() {
            assert_eq!(s.line_col(o), expected[k]);
        }
        for k in [5, 1, 9, 2, 2, 13, 0] {
            assert_eq!(s.line_col(offsets[k]), expected[k]);
        }
    }
}
