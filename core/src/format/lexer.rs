//! Splits scene text into words and braces. `#` starts a comment to the end of the line
//! (an extension; the course files have none).

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

pub fn tokenize(text: &str) -> Vec<Token> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c == b'#' {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
        } else if c == b'{' || c == b'}' {
            let kind = if c == b'{' { TokKind::Open } else { TokKind::Close };
            out.push(Token { kind, start: i, end: i + 1 });
            i += 1;
        } else {
            let start = i;
            while i < bytes.len() && !bytes[i].is_ascii_whitespace() && !matches!(bytes[i], b'{' | b'}' | b'#') {
                i += 1;
            }
            out.push(Token { kind: TokKind::Word, start, end: i });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn braces_split_from_words_and_comments_skipped() {
        let src = "Sphere{center 1 2 3 # note\n radius 1}";
        let toks: Vec<&str> = tokenize(src).iter().map(|t| &src[t.start..t.end]).collect();
        assert_eq!(toks, ["Sphere", "{", "center", "1", "2", "3", "radius", "1", "}"]);
    }
}
