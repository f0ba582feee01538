//! What a word of the scene format may be: the rules a name or a path must keep so that
//! the writer's text reads back as the same scene. The reader (format/) follows them.

/// Whether the reader takes this word as a number (a bad one is an error, never a name).
pub fn is_numberlike(s: &str) -> bool {
    let first = s.as_bytes().first().copied().unwrap_or(b'a');
    first.is_ascii_digit()
        || matches!(first, b'-' | b'+' | b'.')
        || ["nan", "inf", "infinity"]
            .iter()
            .any(|k| s.eq_ignore_ascii_case(k))
}

/// Whether `s` is one word of the format: not empty, no white space, braces, `#` or NUL.
pub fn is_word(s: &str) -> bool {
    !s.is_empty()
        && !s
            .bytes()
            .any(|c| c.is_ascii_whitespace() || matches!(c, b'{' | b'}' | b'#' | 0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_their_look_alikes_are_numberlike_and_names_are_not() {
        for s in ["1", "-x", "+2", ".5", "NaN", "inf", "Infinity"] {
            assert!(is_numberlike(s), "{s}");
        }
        for s in ["radius", "x1", "nano", ""] {
            assert!(!is_numberlike(s), "{s}");
        }
        assert!(is_word("a.obj") && !is_word("a b") && !is_word("") && !is_word("a{"));
    }
}
