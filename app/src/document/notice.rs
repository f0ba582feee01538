//! What the editor tells the user, as typed values: a level and a text. Shown as
//! notifications over the view (`gui::notifications`), never as lines that push the layout.

use std::time::{Duration, Instant};

use tracelab_core::Severity;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// Something done as asked ("exported a.png", "reloaded").
    Info,
    /// Done, but something is lost or was guessed.
    Warning,
    /// Not done, and why.
    Error,
}

impl From<Severity> for Level {
    fn from(s: Severity) -> Self {
        match s {
            Severity::Error => Level::Error,
            Severity::Warning => Level::Warning,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Notice {
    pub level: Level,
    pub text: String,
    /// How many times it was said since it was last dismissed (shown as "×3").
    pub count: u32,
    /// When it was last said.
    pub at: Instant,
}

/// The notices not yet dismissed, oldest first. The same level and text said again is one
/// notice counted twice, moved to the end: a repeated refusal never stacks up.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Notices(Vec<Notice>);

/// More than this and the oldest go: a notification list is not a log.
pub const MAX_NOTICES: usize = 8;

impl Notices {
    pub fn push(&mut self, level: Level, text: impl Into<String>) {
        let text = text.into();
        let count = match self
            .0
            .iter()
            .position(|n| n.level == level && n.text == text)
        {
            Some(i) => self.0.remove(i).count + 1,
            None => 1,
        };
        self.0.push(Notice {
            level,
            text,
            count,
            at: Instant::now(),
        });
        if self.0.len() > MAX_NOTICES {
            self.0.remove(0);
        }
    }

    pub fn info(&mut self, text: impl Into<String>) {
        self.push(Level::Info, text);
    }

    pub fn warning(&mut self, text: impl Into<String>) {
        self.push(Level::Warning, text);
    }

    pub fn error(&mut self, text: impl Into<String>) {
        self.push(Level::Error, text);
    }

    pub fn iter(&self) -> impl DoubleEndedIterator<Item = &Notice> {
        self.0.iter()
    }

    pub fn len(&self) -> usize {
        self.0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    pub fn clear(&mut self) {
        self.0.clear();
    }

    /// Drops the notices of `level` said longer than `after` ago.
    pub fn expire(&mut self, level: Level, after: Duration) {
        self.0
            .retain(|n| n.level != level || n.at.elapsed() < after);
    }

    /// Drops notice `i` (its × button).
    pub fn dismiss(&mut self, i: usize) {
        if i < self.0.len() {
            self.0.remove(i);
        }
    }

    /// Whether any notice's text contains `part` (tests, and callers that look for one).
    pub fn any_contains(&self, part: &str) -> bool {
        self.0.iter().any(|n| n.text.contains(part))
    }

    /// Every text, one a line.
    pub fn joined(&self) -> String {
        self.0
            .iter()
            .map(|n| n.text.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// The most serious level present.
    pub fn worst(&self) -> Option<Level> {
        self.0.iter().map(|n| n.level).max()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_notice_twice_is_one_counted_twice_and_moves_to_the_end() {
        let mut n = Notices::default();
        n.error("Frame selected: select an object first");
        n.info("exported a.png");
        n.error("Frame selected: select an object first");
        assert_eq!(n.len(), 2);
        let last = n.iter().last().expect("one");
        assert_eq!((last.level, last.count), (Level::Error, 2));
        // The same text at another level is another notice.
        n.info("exported a.png");
        n.warning("exported a.png");
        assert_eq!(n.len(), 3);
        assert_eq!(n.worst(), Some(Level::Error));
    }

    #[test]
    fn the_oldest_go_past_the_limit() {
        let mut n = Notices::default();
        for i in 0..MAX_NOTICES + 3 {
            n.info(format!("{i}"));
        }
        assert_eq!(n.len(), MAX_NOTICES);
        assert_eq!(n.iter().next().map(|x| x.text.as_str()), Some("3"));
    }
}
