//! Shared by core's integration tests: the repository's root, private temporary folders, and
//! for the parser fuzz tests a repeatable generator and the token mutations they use.
// Each test binary that includes this module uses only part of it.
#![allow(dead_code, unused_imports)]

use std::path::{Path, PathBuf};

mod data;
pub use data::{course_dir, meshes_dir, perf_dir, semester_dir};

/// The `.txt` files under `dir`, its subfolders included, sorted.
pub fn scene_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        let rd = std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display()));
        for p in rd.filter_map(|e| e.ok().map(|e| e.path())) {
            if p.is_dir() {
                todo.push(p);
            } else if p.extension().is_some_and(|e| e == "txt") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The repository's root (scenes/, assets/).
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// An empty folder of the system's temporary folder, private to this test process:
/// `tracelab-{area}-{pid}-{name}`, emptied first.
pub fn temp_dir(area: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tracelab-{area}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// xorshift64: the same inputs on every run.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// `words` with 1 to `max_edits` random edits (a token removed, one of `extra` inserted, or a
/// token replaced by another of `words`), joined by spaces.
pub fn mutate(words: &[&str], extra: &[&str], max_edits: usize, rng: &mut Rng) -> String {
    let mut w = words.to_vec();
    for _ in 0..1 + rng.below(max_edits) {
        match rng.below(3) {
            0 if !w.is_empty() => {
                let i = rng.below(w.len());
                w.remove(i);
            }
            1 => {
                let i = rng.below(w.len() + 1);
                w.insert(i, extra[rng.below(extra.len())]);
            }
            _ if !w.is_empty() => {
                let i = rng.below(w.len());
                w[i] = words[rng.below(words.len())];
            }
            _ => {}
        }
    }
    w.join(" ")
}

impl Rng {
    /// The generator for case `k` of a run seeded with `seed` (splitmix64 of both), so any one
    /// case can be replayed alone.
    pub fn for_case(seed: u64, k: u64) -> Rng {
        let mut z = seed ^ k.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        Rng((z ^ (z >> 31)) | 1)
    }
}

/// Numbers that break careless readers: overflow, underflow, signs, specials, other bases.
pub const NASTY_NUMBERS: &[&str] = &[
    "1e39",
    "-1e39",
    "1e308",
    "-1e308",
    "1e-45",
    "1e-50",
    "-0",
    "0",
    "-1",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "infinity",
    "0x10",
    "0b1",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "3.4028235e38",
    "3.4028236e38",
    "1.",
    ".5",
    "+1",
    "1e",
    "--1",
    "1_000",
    "1,5",
    "00007",
    "-2147483649",
];

/// Numbers any reader must take.
pub const PLAIN_NUMBERS: &[&str] = &[
    "2", "0.5", "-3", "1e-3", "7", "0.25", "-0.75", "10", "1", "3",
];

/// Bytes that must be rejected or escaped: NUL, invalid UTF-8, ESC, vertical tab, DEL, a
/// bidi override.
pub const NASTY_BYTES: &[&[u8]] = &[
    b"\0",
    b"\xff",
    b"\x80",
    b"\xc3",
    b"\x1b[31m",
    b"\x0b",
    b"\x7f",
    b"\r",
    b"\t",
    "\u{202e}".as_bytes(),
    b"#",
];

/// `seed` with 1 to 4 random edits: a token deleted, duplicated or swapped with another, a
/// number replaced by a nasty one, a brace inserted or removed, a nasty byte inserted, or
/// the text truncated. Tokens are rejoined with their original spacing.
pub fn mutate_text(seed: &[u8], extra_words: &[&str], rng: &mut Rng) -> Vec<u8> {
    // (token, separator after it)
    let text = String::from_utf8_lossy(seed);
    let mut toks: Vec<(Vec<u8>, Vec<u8>)> = Vec::new();
    let mut rest = text.as_ref();
    while !rest.is_empty() {
        let start = rest
            .find(|c: char| !c.is_ascii_whitespace())
            .unwrap_or(rest.len());
        if start > 0 {
            match toks.last_mut() {
                Some(t) => t.1.extend_from_slice(&rest.as_bytes()[..start]),
                None => toks.push((Vec::new(), rest.as_bytes()[..start].to_vec())),
            }
        }
        rest = &rest[start..];
        let end = rest
            .find(|c: char| c.is_ascii_whitespace())
            .unwrap_or(rest.len());
        if end > 0 {
            toks.push((rest.as_bytes()[..end].to_vec(), Vec::new()));
        }
        rest = &rest[end..];
    }
    let mut truncate = None;
    let mut inserts: Vec<&[u8]> = Vec::new();
    // Mostly one edit: several at once are nearly always rejected.
    let edits = [1, 1, 1, 2, 3, 4][rng.below(6)];
    for _ in 0..edits {
        let n = toks.len();
        let i = rng.below(n);
        match rng.below(10) {
            0 if n > 0 => {
                toks.remove(i);
            }
            1 if n > 0 => {
                let t = toks[i].clone();
                toks.insert(i, t);
            }
            2 if n > 1 => {
                let j = rng.below(n);
                let (a, b) = (toks[i].0.clone(), toks[j].0.clone());
                toks[i].0 = b;
                toks[j].0 = a;
            }
            3 | 4 => {
                // Replace a number (or any token, when there is none nearby).
                let numbers: Vec<usize> = (0..n)
                    .filter(|&k| {
                        toks[k]
                            .0
                            .first()
                            .is_some_and(|c| c.is_ascii_digit() || *c == b'-')
                    })
                    .collect();
                let k = if numbers.is_empty() {
                    i
                } else {
                    numbers[rng.below(numbers.len())]
                };
                if let Some(t) = toks.get_mut(k) {
                    // Half nasty, half plain, so that many mutated scenes are still accepted.
                    let pool = if rng.below(2) == 0 {
                        NASTY_NUMBERS
                    } else {
                        PLAIN_NUMBERS
                    };
                    t.0 = pool[rng.below(pool.len())].as_bytes().to_vec();
                }
            }
            5 => {
                let brace = if rng.below(2) == 0 {
                    b"{".to_vec()
                } else {
                    b"}".to_vec()
                };
                toks.insert(rng.below(n + 1), (brace, b" ".to_vec()));
            }
            6 if n > 0 => {
                let braces: Vec<usize> = (0..n)
                    .filter(|&k| toks[k].0 == b"{" || toks[k].0 == b"}")
                    .collect();
                if !braces.is_empty() {
                    toks.remove(braces[rng.below(braces.len())]);
                }
            }
            7 => inserts.push(NASTY_BYTES[rng.below(NASTY_BYTES.len())]),
            8 if !extra_words.is_empty() => {
                let w = extra_words[rng.below(extra_words.len())]
                    .as_bytes()
                    .to_vec();
                toks.insert(rng.below(n + 1), (w, b" ".to_vec()));
            }
            _ => truncate = Some(rng.next()),
        }
    }
    let mut out: Vec<u8> = toks
        .into_iter()
        .flat_map(|(t, s)| t.into_iter().chain(s))
        .collect();
    for b in inserts {
        let at = rng.below(out.len() + 1);
        out.splice(at..at, b.iter().copied());
    }
    if let Some(r) = truncate {
        out.truncate((r % (out.len() as u64 + 1)) as usize);
    }
    out
}

/// How many cases a fuzz test runs: `TRACELAB_FUZZ_CASES`, else `default`.
pub fn fuzz_cases(default: u64) -> u64 {
    std::env::var("TRACELAB_FUZZ_CASES")
        .ok()
        .and_then(|v| v.replace('_', "").parse().ok())
        .unwrap_or(default)
}

/// The input as a Rust byte-string literal, to paste into a regression test.
pub fn quoted(bytes: &[u8]) -> String {
    format!("b\"{}\"", bytes.escape_ascii())
}
