//! The lexer's tokens, made a chunk of text at a time. A whole file's token list costs 24
//! bytes per token — 24 times the text for a file of braces (1.5 GB for 60 MB of `{`) — while
//! one chunk's is small. Comments are kept whole: the scene keeps them anyway.

use std::cell::RefCell;

use super::lexer::{Comment, Token, tokenize_with_comments};

/// Text per chunk. Chunks end after a newline, or inside a very long line at a space or
/// brace before any `#` on that line, so no token or comment is split.
const CHUNK: usize = 1 << 16;

pub struct TokenStream<'a> {
    text: &'a str,
    state: RefCell<State>,
}

#[derive(Default)]
struct State {
    /// Index, in the whole file's token sequence, of `tokens[0]`.
    first: usize,
    /// The current chunk's tokens.
    tokens: Vec<Token>,
    /// Every comment of the chunks read so far, with file-wide token indices.
    comments: Vec<Comment>,
    /// Where the next chunk starts.
    next_chunk: usize,
}

impl<'a> TokenStream<'a> {
    pub fn new(text: &'a str) -> Self {
        // A UTF-8 byte-order mark (some Windows editors write one) is not part of the first
        // word: skipped, as whitespace is.
        let start = if text.starts_with('\u{feff}') { 3 } else { 0 };
        TokenStream {
            text,
            state: RefCell::new(State {
                next_chunk: start,
                ..State::default()
            }),
        }
    }

    /// Token number `i` of the file. Indices must not go back before the current chunk: the
    /// parser only moves forward, looking at most at the token after the one it read.
    pub fn get(&self, i: usize) -> Option<Token> {
        let mut s = self.state.borrow_mut();
        while i >= s.first + s.tokens.len() && s.next_chunk < self.text.len() {
            self.read_chunk(&mut s);
        }
        debug_assert!(
            i >= s.first || s.tokens.is_empty(),
            "token {i} is behind the stream"
        );
        i.checked_sub(s.first)
            .and_then(|k| s.tokens.get(k))
            .copied()
    }

    /// Comment number `k` of the file, once the chunk holding the token after it was read
    /// (every comment before a token the parser has seen).
    pub fn comment(&self, k: usize) -> Option<Comment> {
        self.state.borrow().comments.get(k).copied()
    }

    /// The number of tokens in the whole file (reads the rest of it).
    pub fn len(&self) -> usize {
        let mut s = self.state.borrow_mut();
        while s.next_chunk < self.text.len() {
            self.read_chunk(&mut s);
        }
        s.first + s.tokens.len()
    }

    fn read_chunk(&self, s: &mut State) {
        let start = s.next_chunk;
        let end = chunk_end(self.text, start);
        // Chunks end after ASCII bytes, so both ends are char boundaries.
        let (mut tokens, comments) =
            tokenize_with_comments(self.text.get(start..end).unwrap_or(""));
        for t in &mut tokens {
            t.start += start;
            t.end += start;
        }
        s.first += s.tokens.len();
        let first = s.first;
        s.comments.extend(comments.into_iter().map(|c| Comment {
            start: c.start + start,
            end: c.end + start,
            next_token: c.next_token + first,
        }));
        s.tokens = tokens;
        s.next_chunk = end;
    }
}

/// The end of the chunk that starts at `start` (a line start, or a mid-line point with no `#`
/// before it on its line).
fn chunk_end(text: &str, start: usize) -> usize {
    let bytes = text.as_bytes();
    let target = start + CHUNK;
    if target >= bytes.len() {
        return bytes.len();
    }
    let line_start = bytes[start..target]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(start, |i| start + i + 1);
    let mut comment = bytes[line_start..target].contains(&b'#');
    for (i, &b) in bytes.iter().enumerate().skip(target) {
        match b {
            b'\n' => return i + 1,
            b'#' => comment = true,
            b'{' | b'}' if !comment => return i + 1,
            _ if b.is_ascii_whitespace() && !comment => return i + 1,
            _ => {}
        }
    }
    bytes.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &str) -> (Vec<Token>, Vec<Comment>) {
        let s = TokenStream::new(text);
        let tokens: Vec<Token> = (0..).map_while(|i| s.get(i)).collect();
        assert_eq!(s.len(), tokens.len());
        let comments = (0..).map_while(|k| s.comment(k)).collect();
        (tokens, comments)
    }

    #[test]
    fn chunked_tokens_and_comments_are_the_whole_file_ones() {
        let word = "x".repeat(CHUNK + 7);
        for text in [
            format!("{}\nSphere {{ center 1 2 3 # c }}\n", "a ".repeat(CHUNK)),
            format!("{}}}# {{ b\n{{", "{ ".repeat(CHUNK / 2 + 3)),
            format!("{}{{", "}".repeat(3 * CHUNK + 1)),
            format!("{word} {word}\n{word}"),
            format!("a{}# {} {{\n}}", " ".repeat(CHUNK), "z ".repeat(CHUNK)),
            format!("{}#tail", "# c\n{ ".repeat(CHUNK / 3)),
            "é".repeat(CHUNK),
            String::new(),
        ] {
            assert_eq!(all(&text), tokenize_with_comments(&text));
        }
    }
}
