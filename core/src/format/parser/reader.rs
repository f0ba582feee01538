//! Tokens, comments and messages: what every part of the parser reads and reports through.

use super::super::diagnostic::Severity;
use super::super::lexer::{TokKind, Token};
use super::{Located, MAX_SHOWN, Parser, UnshownSummary, is_numberlike};

impl<'a> Parser<'a> {
    pub(super) fn peek(&self) -> Option<Token> {
        // Out of memory, the parse stops: the rest of the file is not read.
        if self.out_of_memory {
            return None;
        }
        self.toks.get(self.pos)
    }

    pub(super) fn next(&mut self) -> Option<Token> {
        let t = self.peek();
        if t.is_some() {
            self.pos += 1;
        }
        t
    }

    /// Takes the comments that stand before token `tok`, which starts something the scene
    /// keeps comments for (a keyword, a field, a closing brace). Earlier comments nobody
    /// took stood inside something (between a keyword and its value) and are lost.
    pub(super) fn comments_before(&mut self, tok: usize) -> Vec<String> {
        let mut out = std::mem::take(&mut self.pending_comments);
        while let Some(c) = self.toks.comment(self.next_comment) {
            if c.next_token > tok {
                break;
            }
            self.next_comment += 1;
            let text: &'a str = self.src.text;
            if c.next_token == tok {
                out.push(text[c.start..c.end].to_string());
            } else {
                let d = self.src.diagnostic(
                    Severity::Warning,
                    c.start.saturating_sub(1),
                    "this comment stands inside a value (between a keyword and what it takes), where it cannot be kept: saving the scene drops it",
                );
                self.lost_comments.push(d.clone());
                self.diags.push(d);
            }
        }
        out
    }

    /// Comments before the token just read (`self.pos - 1`).
    pub(super) fn comments_here(&mut self) -> Vec<String> {
        self.comments_before(self.pos.saturating_sub(1))
    }

    /// Comments before the token just read belong to what comes next (a MaterialIndex's to
    /// the object it applies to).
    pub(super) fn defer_comments(&mut self) {
        self.pending_comments = self.comments_here();
    }

    pub(super) fn text(&self, t: Token) -> &'a str {
        let text: &'a str = self.src.text;
        &text[t.start..t.end]
    }

    /// The word that starts at `offset`, as written (for quoting numbers in messages).
    pub(super) fn word_at(&self, offset: usize) -> &'a str {
        let text: &'a str = self.src.text;
        let rest = text.get(offset..).unwrap_or("");
        let end = rest
            .find(|c: char| c.is_ascii_whitespace() || matches!(c, '{' | '}' | '#'))
            .unwrap_or(rest.len());
        &rest[..end]
    }

    /// How a token reads in a "found …" message.
    pub(super) fn describe(&self, t: Option<Token>) -> (String, usize) {
        match t {
            Some(t) => (format!("\"{}\"", self.text(t)), t.start),
            None => ("the end of the file".to_string(), self.src.text.len()),
        }
    }

    pub(super) fn error(&mut self, offset: usize, msg: impl Into<String>) {
        self.fatal = true;
        self.report(Severity::Error, offset, msg);
    }

    pub(super) fn warn(&mut self, offset: usize, msg: impl Into<String>) {
        self.report(Severity::Warning, offset, msg);
    }

    fn report(&mut self, severity: Severity, offset: usize, msg: impl Into<String>) {
        let u = &mut self.unshown;
        let (shown, unshown) = match severity {
            Severity::Error => (&mut u.shown_errors, &mut u.errors),
            Severity::Warning => (&mut u.shown_warnings, &mut u.warnings),
        };
        if *shown < MAX_SHOWN {
            *shown += 1;
            let d = self.src.diagnostic(severity, offset, msg);
            self.diags.push(d);
        } else {
            if unshown.0 == 0 {
                unshown.1 = offset;
            }
            unshown.0 += 1;
        }
    }

    /// "… and N more", located at the first diagnostic left out.
    pub(super) fn summarise_unshown(&mut self) -> UnshownSummary {
        let u = &self.unshown;
        let mut out = UnshownSummary::default();
        for (severity, (n, at), what) in [
            (Severity::Error, u.errors, "error"),
            (Severity::Warning, u.warnings, "warning"),
        ] {
            if n > 0 {
                let s = if n == 1 { "" } else { "s" };
                let d = self
                    .src
                    .diagnostic(severity, at, format!("… and {n} more {what}{s}"));
                let place = Some(Located {
                    file: d.file.clone(),
                    line: d.line,
                    col: d.col,
                });
                match severity {
                    Severity::Error => out.errors = (n, place),
                    Severity::Warning => out.warnings = (n, place),
                }
                out.summaries += 1;
                self.diags.push(d);
            }
        }
        out
    }

    /// Skips to just past the `}` that closes a block whose `{` was already read.
    pub(super) fn skip_block(&mut self) {
        let mut depth = 1usize;
        while let Some(t) = self.next() {
            match t.kind {
                TokKind::Open => depth += 1,
                TokKind::Close => {
                    depth -= 1;
                    if depth == 0 {
                        return;
                    }
                }
                TokKind::Word => {}
            }
        }
    }

    /// Reads the `{` after a keyword; on failure reports it and returns None.
    pub(super) fn expect_open(&mut self, keyword: &str) -> Option<usize> {
        match self.peek() {
            Some(t) if t.kind == TokKind::Open => {
                self.pos += 1;
                Some(t.start)
            }
            other => {
                let (found, off) = self.describe(other);
                self.error(
                    off,
                    format!("expected \"{{\" after \"{keyword}\", found {found}"),
                );
                None
            }
        }
    }

    /// A whole number after `keyword` (numObjects, MaterialIndex, …).
    pub(super) fn expect_count(&mut self, keyword: &str) -> Option<(usize, usize)> {
        let t = self.peek();
        if let Some(t) = t.filter(|t| t.kind == TokKind::Word) {
            if let Ok(n) = self.text(t).parse::<usize>() {
                self.pos += 1;
                return Some((n, t.start));
            }
            if is_numberlike(self.text(t)) {
                self.pos += 1;
                let msg = format!(
                    "expected a whole number after \"{keyword}\", found \"{}\"",
                    self.text(t)
                );
                self.error(t.start, msg);
                return None;
            }
        }
        let (found, off) = self.describe(t);
        self.error(
            off,
            format!("expected a whole number after \"{keyword}\", found {found}"),
        );
        None
    }

    /// Reads one number token; reports bad and non-finite numbers.
    pub(super) fn number_token(&mut self, t: Token, after: &str) -> Option<f32> {
        let s = self.text(t);
        match s.parse::<f32>() {
            Ok(v) if v.is_finite() => Some(v),
            Ok(_) => {
                self.error(
                    t.start,
                    format!("\"{s}\" after \"{after}\" is not a finite number"),
                );
                None
            }
            Err(_) => {
                self.error(
                    t.start,
                    format!("expected a number after \"{after}\", found \"{s}\""),
                );
                None
            }
        }
    }

    /// Exactly `n` numbers after `keyword` (for transform ops).
    pub(super) fn expect_numbers(&mut self, keyword: &str, n: usize) -> Option<Vec<f32>> {
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let t = self.peek();
            match t {
                Some(t) if t.kind == TokKind::Word && is_numberlike(self.text(t)) => {
                    self.pos += 1;
                    out.push(self.number_token(t, keyword)?);
                }
                other => {
                    let (found, off) = self.describe(other);
                    let what = if n == 1 {
                        "a number".to_string()
                    } else {
                        format!("{n} numbers")
                    };
                    self.error(
                        off,
                        format!("expected {what} after \"{keyword}\", found {found}"),
                    );
                    return None;
                }
            }
        }
        Some(out)
    }
}
