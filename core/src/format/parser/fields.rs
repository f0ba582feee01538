//! A flat block's `name value…` lines (a camera, a light, a material, a primitive): read all,
//! then taken by name, so a missing, repeated or unknown field is named once.

use glam::Vec3;

use super::super::lexer::TokKind;
use super::{Parser, is_numberlike};
use crate::scene::{Anchor, Comments};

/// Numbers one field may hold: far above the grammar's largest (Matrix, 16), and small
/// enough that a field of millions of numbers is refused rather than held.
pub(super) const MAX_FIELD_NUMBERS: usize = 1024;

/// One `name value…` line inside a flat block.
pub(super) struct Field {
    pub(super) name: String,
    pub(super) name_off: usize,
    pub(super) values: Vec<(f32, usize)>,
    pub(super) word: Option<(String, usize)>,
    /// Text and offset of the token after the values, for "found …" in messages.
    pub(super) after: (String, usize),
    pub(super) used: bool,
    /// Named as the "found …" of a field short of numbers: never reported as unknown, but
    /// still taken if it is a real field (`center 0 0 radius 1` must not also say radius
    /// is missing).
    pub(super) swallowed: bool,
    /// Comments before the field's name.
    pub(super) comments: Vec<String>,
}

/// An item's comments: those before its keyword, before each field, and before its `}`.
pub(super) fn block_comments(
    before: Vec<String>,
    fields: &mut [Field],
    end: Vec<String>,
) -> Comments {
    let mut c = Comments {
        before,
        end,
        ..Comments::default()
    };
    for f in fields.iter_mut().filter(|f| !f.comments.is_empty()) {
        c.inner
            .entry(Anchor::Field(f.name.clone()))
            .or_default()
            .append(&mut f.comments);
    }
    c
}

impl Parser<'_> {
    /// Reads `name numbers…` lines up to the closing `}` of a block whose `{` was read.
    /// Returns None (having reported why) if the block is malformed.
    pub(super) fn read_fields(
        &mut self,
        block: &str,
        open: usize,
    ) -> Option<(Vec<Field>, Vec<String>)> {
        let mut fields: Vec<Field> = Vec::new();
        let mut ok = true;
        let end_comments;
        loop {
            let Some(t) = self.next() else {
                self.error(
                    open,
                    format!(
                        "unterminated {block} block: expected \"}}\" before the end of the file"
                    ),
                );
                return None;
            };
            match t.kind {
                TokKind::Close => {
                    end_comments = self.comments_here();
                    break;
                }
                TokKind::Open => {
                    self.error(t.start, format!("unexpected \"{{\" inside {block}"));
                    self.skip_block();
                    ok = false;
                }
                TokKind::Word => {
                    let name = self.text(t);
                    if is_numberlike(name) {
                        if ok {
                            let msg = match fields.last() {
                                Some(f) if f.values.is_empty() && f.word.is_none() => {
                                    format!(
                                        "expected a number after \"{}\", found \"{name}\"",
                                        f.name
                                    )
                                }
                                _ => format!("unexpected number \"{name}\" in {block}"),
                            };
                            self.error(t.start, msg);
                        }
                        ok = false;
                        continue;
                    }
                    let comments = self.comments_here();
                    let mut field = Field {
                        comments,
                        name: name.to_string(),
                        name_off: t.start,
                        values: Vec::new(),
                        word: None,
                        after: (String::new(), 0),
                        used: false,
                        swallowed: false,
                    };
                    if name == "obj_file" {
                        match self.peek() {
                            Some(w) if w.kind == TokKind::Word => {
                                self.pos += 1;
                                field.word = Some((self.text(w).to_string(), w.start));
                            }
                            other => {
                                let (found, off) = self.describe(other);
                                self.error(
                                    off,
                                    format!(
                                        "expected a file name after \"obj_file\", found {found}"
                                    ),
                                );
                                ok = false;
                            }
                        }
                    } else {
                        let mut too_many = None;
                        while let Some(v) = self.peek().filter(|v| v.kind == TokKind::Word) {
                            if !is_numberlike(self.text(v)) {
                                break;
                            }
                            self.pos += 1;
                            if field.values.len() == MAX_FIELD_NUMBERS {
                                // Skipped, not kept: memory stays bounded by what a scene keeps.
                                too_many.get_or_insert(v.start);
                                continue;
                            }
                            match self.number_token(v, name) {
                                Some(x) => field.values.push((x, v.start)),
                                None => ok = false,
                            }
                        }
                        if let Some(off) = too_many {
                            self.error(
                                off,
                                format!("\"{name}\" takes at most {MAX_FIELD_NUMBERS} numbers"),
                            );
                            ok = false;
                        }
                    }
                    field.after = self.describe(self.peek());
                    fields.push(field);
                }
            }
        }
        ok.then_some((fields, end_comments))
    }

    /// Takes field `name` with exactly `n` numbers; reports what is wrong otherwise.
    pub(super) fn take(
        &mut self,
        fields: &mut [Field],
        block: &str,
        block_off: usize,
        name: &str,
        n: usize,
    ) -> Option<Vec<f32>> {
        let Some(i) = fields
            .iter()
            .position(|f| f.name == name && (!f.used || f.swallowed))
        else {
            self.error(block_off, format!("{block} is missing \"{name}\""));
            return None;
        };
        fields[i].used = true;
        fields[i].swallowed = false;
        let f = &fields[i];
        if f.values.len() < n {
            let what = if n == 1 {
                "a number".to_string()
            } else {
                format!("{n} numbers")
            };
            let (found, off) = f.after.clone();
            // The word found instead of a number is not a field of its own: do not report
            // it again as unknown.
            if let Some(next) = fields.get_mut(i + 1).filter(|g| g.name_off == off) {
                next.used = true;
                next.swallowed = true;
            }
            self.error(
                off,
                format!("expected {what} after \"{name}\", found {found}"),
            );
            return None;
        }
        if f.values.len() > n {
            let off = f.values[n].1;
            let extra = self.word_at(off);
            self.error(
                off,
                format!("\"{name}\" takes {n} number(s); found an extra \"{extra}\""),
            );
            return None;
        }
        Some(f.values.iter().map(|v| v.0).collect())
    }

    pub(super) fn take_vec3(
        &mut self,
        fields: &mut [Field],
        block: &str,
        off: usize,
        name: &str,
    ) -> Option<Vec3> {
        self.take(fields, block, off, name, 3)
            .map(|v| Vec3::new(v[0], v[1], v[2]))
    }

    pub(super) fn take_f32(
        &mut self,
        fields: &mut [Field],
        block: &str,
        off: usize,
        name: &str,
    ) -> Option<f32> {
        self.take(fields, block, off, name, 1).map(|v| v[0])
    }

    /// Where field `name` of a block is written, to place a rule's message on it.
    pub(super) fn field_offset(&self, fields: &[Field], name: &str) -> Option<usize> {
        fields.iter().find(|f| f.name == name).map(|f| f.name_off)
    }

    /// Reports fields nobody took (unknown or repeated names).
    pub(super) fn reject_unused(&mut self, fields: &[Field], block: &str, expected: &str) -> bool {
        let mut ok = true;
        for f in fields.iter().filter(|f| !f.used) {
            let repeated = fields.iter().any(|g| g.used && g.name == f.name);
            let msg = if repeated {
                format!("\"{}\" is given twice in {block}", f.name)
            } else {
                format!(
                    "unknown field \"{}\" in {block} (expected {expected})",
                    f.name
                )
            };
            self.error(f.name_off, msg);
            ok = false;
        }
        ok
    }
}
