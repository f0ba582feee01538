//! `#` comments kept with what they were written next to, so open → edit → save keeps them.
//! Each string is one comment line without its `#` (trailing spaces dropped); the writer
//! prints it back as `#` + text on a line of its own, indented like what it belongs to.

use std::collections::BTreeMap;

/// Where inside a block a comment stood: before a field line, or before a Transform's op.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Anchor {
    /// Before the line naming this field (`radius`, `numObjects`, `diffuseColor`, …).
    Field(String),
    /// Before the Transform's operation at this position.
    Op(usize),
}

/// The comments of one item: a node, a light, a material or a top-level block.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Comments {
    /// Lines before the item's keyword.
    pub before: Vec<String>,
    /// Lines before one of the item's own lines. A map, so the order fields were written in
    /// does not matter to equality (the writer writes fields in its own order).
    pub inner: BTreeMap<Anchor, Vec<String>>,
    /// Lines after the item's last line, before its closing `}`.
    pub end: Vec<String>,
}

impl Comments {
    pub fn is_empty(&self) -> bool {
        self.before.is_empty() && self.inner.is_empty() && self.end.is_empty()
    }

    /// Every line, in no particular order (for counting and searching).
    pub fn lines(&self) -> impl Iterator<Item = &String> {
        self.before
            .iter()
            .chain(self.inner.values().flatten())
            .chain(&self.end)
    }

    /// Keeps op comments with their ops after op `index` was removed: its own go with it,
    /// later ones move down one place.
    pub fn remove_op(&mut self, index: usize) {
        self.remap_ops(|i| match i.cmp(&index) {
            std::cmp::Ordering::Less => Some(i),
            std::cmp::Ordering::Equal => None,
            std::cmp::Ordering::Greater => Some(i - 1),
        });
    }

    /// Keeps op comments with their ops after op `from` moved to position `to`.
    pub fn move_op(&mut self, from: usize, to: usize) {
        self.remap_ops(|i| {
            Some(if i == from {
                to
            } else if from < to && i > from && i <= to {
                i - 1
            } else if to < from && i >= to && i < from {
                i + 1
            } else {
                i
            })
        });
    }

    fn remap_ops(&mut self, f: impl Fn(usize) -> Option<usize>) {
        let old = std::mem::take(&mut self.inner);
        for (anchor, lines) in old {
            let anchor = match anchor {
                Anchor::Op(i) => match f(i) {
                    Some(j) => Anchor::Op(j),
                    None => continue,
                },
                a => a,
            };
            self.inner.entry(anchor).or_default().extend(lines);
        }
    }
}

/// Comments of the top-level blocks that are not items of their own. The top-level Group's
/// are on the graph's root node.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneComments {
    pub camera: Comments,
    pub lights: Comments,
    pub background: Comments,
    pub materials: Comments,
    /// Lines after the last block, at the end of the file.
    pub end: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ops(c: &Comments) -> Vec<(usize, &str)> {
        c.inner
            .iter()
            .filter_map(|(a, l)| match a {
                Anchor::Op(i) => Some((*i, l[0].as_str())),
                Anchor::Field(_) => None,
            })
            .collect()
    }

    fn three_ops() -> Comments {
        let mut c = Comments::default();
        for (i, t) in ["a", "b", "c"].iter().enumerate() {
            c.inner.insert(Anchor::Op(i), vec![t.to_string()]);
        }
        c
    }

    #[test]
    fn op_comments_follow_their_ops_through_remove_and_move() {
        let mut c = three_ops();
        c.remove_op(1);
        assert_eq!(ops(&c), [(0, "a"), (1, "c")]);
        let mut c = three_ops();
        c.move_op(0, 2);
        assert_eq!(ops(&c), [(0, "b"), (1, "c"), (2, "a")]);
        let mut c = three_ops();
        c.move_op(2, 0);
        assert_eq!(ops(&c), [(0, "c"), (1, "a"), (2, "b")]);
    }
}
