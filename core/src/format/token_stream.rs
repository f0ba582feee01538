//! The lexer's tokens, made a chunk of text at a time: a whole file's token list costs 24
//! bytes per token, 24 times the text for a file of braces, while one chunk's is small.

use std::cell::RefCell;

use super::lexer::{Token, tokenize};

/// Text per chunk. Chunks end after a newline, or inside a very long line at a space or brace
/// before any `#` on that line, so no token or comment is split.
const CHUNK: usize = 1 << 16;

pub struct TokenStream<'a> {
    text: &'a str,
    window: RefCell<Window>,
}

#[derive(Default)]
struct Window {
    /// Index, in the whole file's token sequence, of `tokens[0]`.
    first: usize,
    tokens: Vec<Token>,
    /// Where the next chunk starts.
    next_chunk: usize,
}

impl<'a> TokenStream<'a> {
    pub fn new(text: &'a str) -> Self {
        TokenStream { text, window: RefCell::new(Window::default()) }
    }

    /// Token number `i` of the file. Indices must not go back before the last chunk read:
    /// the parser only moves forward, one token past the one it has looked at.
    pub fn get(&self, i: usize) -> Option<Token> {
        let mut w = self.window.borrow_mut();
        while i >= w.first + w.tokens.len() {
            if w.next_chunk >= self.text.len() {
                return None;
            }
            let start = w.next_chunk;
            let end = chunk_end(self.text, start);
            let mut tokens = tokenize(self.text.get(start..end).unwrap_or(""));
            for t in &mut tokens {
                t.start += start;
                t.end += start;
            }
            w.first += w.tokens.len();
            w.tokens = tokens;
            w.next_chunk = end;
        }
        i.checked_sub(w.first).and_then(|k| w.tokens.get(k)).copied()
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
    let line_start = bytes[start..target].iter().rposition(|&b| b == b'\n').map_or(start, |i| start + i + 1);
    let mut comment = bytes[line_start..target].contains(&b'#');
    for (i, &b) in bytes.iter().enumerate().skip(target) {
        match b {
            b'\n' => return i + 1,
            b'#' => comment = true,
            b'{' | b'}' => {
                if !comment {
                    return i + 1;
                }
            }
            _ if b.is_ascii_whitespace() && !comment => return i + 1,
            _ => {}
        }
    }
    bytes.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &str) -> Vec<Token> {
        let s = TokenStream::new(text);
        (0..).map_while(|i| s.get(i)).collect()
    }

    #[test]
    fn chunked_tokens_are_the_whole_file_tokens() {
        let word = "x".repeat(CHUNK + 7);
        for text in [
            format!("{}\nSphere {{ center 1 2 3 # c }}\n", "a ".repeat(CHUNK)),
            format!("{}}}# {{ b\n{{", "{ ".repeat(CHUNK / 2 + 3)),
            format!("{}{{", "}".repeat(3 * CHUNK + 1)),
            format!("{word} {word}\n{word}"),
            format!("a{}# {} {{\n}}", " ".repeat(CHUNK), "z ".repeat(CHUNK)),
            "é".repeat(CHUNK),
            String::new(),
        ] {
            assert_eq!(all(&text), tokenize(&text));
        }
    }
}
