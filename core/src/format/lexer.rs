//! Splits scene text into words and braces. `#` starts a comment to the end of the line
//! (an extension; the course files have none). Comments come back beside the tokens, not
//! among them, so the grammar never sees them; the parser attaches each one to what follows.

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TokKind {
    Word,
    Open,
    Close,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Token {
    pub kind: TokKind,
    pub start: usize,
    pub end: usize,
}

/// One `#` comment: `start..end` spans the text after `#` to the end of the line (trailing
/// whitespace excluded); `next_token` is the index of the token that follows it
/// (`tokens.len()` at the end of the file).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Comment {
    pub start: usize,
    pub end: usize,
    pub next_token: usize,
}

pub fn tokenize_with_comments(text: &str) -> (Vec<Token>, Vec<Comment>) {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut comments = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c == b'#' {
            let start = i + 1;
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
            // Trimming ASCII whitespace keeps `end` on a char boundary.
            let end = start + text[start..i].trim_end().len();
            comments.push(Comment {
                start,
                end,
                next_token: out.len(),
            });
        } else if c == b'{' || c == b'}' {
            let kind = if c == b'{' {
                TokKind::Open
            } else {
                TokKind::Close
            };
            out.push(Token {
                kind,
                start: i,
                end: i + 1,
            });
            i += 1;
        } else {
            let start = i;
            while i < bytes.len()
                && !bytes[i].is_ascii_whitespace()
                && !matches!(bytes[i], b'{' | b'}' | b'#')
            {
                i += 1;
            }
            out.push(Token {
                kind: TokKind::Word,
                start,
                end: i,
            });
        }
    }
    (out, comments)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn braces_split_from_words_and_comments_skipped() {
        let src = "Sphere{center 1 2 3 # note\n radius 1}";
        let toks: Vec<&str> = tokenize_with_comments(src)
            .0
            .iter()
            .map(|t| &src[t.start..t.end])
            .collect();
        assert_eq!(
            toks,
            ["Sphere", "{", "center", "1", "2", "3", "radius", "1", "}"]
        );
    }

    #[test]
    fn comments_come_back_with_the_token_they_precede() {
        let src = "# head \r\nA {# in\n}\n#tail";
        let (toks, comments) = tokenize_with_comments(src);
        let got: Vec<(&str, usize)> = comments
            .iter()
            .map(|c| (&src[c.start..c.end], c.next_token))
            .collect();
        assert_eq!(got, [(" head", 0), (" in", 2), ("tail", 3)]);
        assert_eq!(toks.len(), 3);
    }
}
