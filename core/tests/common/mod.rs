//! Shared by the parser fuzz tests: a repeatable generator and the token mutations they use.

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
