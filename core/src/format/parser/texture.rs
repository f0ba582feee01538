//! The solid textures of a Materials block (assignment 6): `Checkerboard`, `Noise`,
//! `Marble` and `Wood`, each an optional `Transform { ops }`, two `materialIndex` lines and,
//! by kind, `octaves`, `frequency` and `amplitude`.

use super::super::lexer::TokKind;
use super::{Parser, TextureRefs, is_numberlike};
use crate::scene::{Anchor, Comments, Material, SolidTexture, TextureKind, validate};

impl Parser<'_> {
    /// A texture block after its keyword; None (reported) when it is broken, with the
    /// reader moved past the block's `}` so the rest of the Materials block reads on.
    pub(super) fn parse_texture_block(
        &mut self,
        kind: TextureKind,
        off: usize,
    ) -> Option<Material> {
        let start = self.pos;
        let m = self.read_texture_block(kind, off);
        if m.is_none() && self.peek().is_some() {
            // How many of the blocks opened since the keyword are still open.
            let mut depth = 0usize;
            for i in start..self.pos {
                match self.toks.get(i).map(|t| t.kind) {
                    Some(TokKind::Open) => depth += 1,
                    Some(TokKind::Close) => depth = depth.saturating_sub(1),
                    _ => {}
                }
            }
            for _ in 0..depth {
                self.skip_block();
            }
        }
        m
    }

    fn read_texture_block(&mut self, kind: TextureKind, off: usize) -> Option<Material> {
        let kw = kind.name();
        let mut comments = Comments {
            before: self.comments_here(),
            ..Comments::default()
        };
        self.expect_open(kw)?;
        let mut transform: Option<Vec<_>> = None;
        let mut indices: Vec<(u32, usize)> = Vec::new();
        let mut octaves = None;
        let mut waves: [Option<f32>; 2] = [None, None];
        // (field, offset) for the rules' errors.
        let mut offsets: Vec<(&'static str, usize)> = Vec::new();
        let mut op_offsets = Vec::new();
        let mut ok = true;
        let expected = match (kind.has_octaves(), kind.has_waves()) {
            (false, _) => "Transform or materialIndex",
            (true, false) => "Transform, materialIndex or octaves",
            (true, true) => "Transform, materialIndex, octaves, frequency or amplitude",
        };
        loop {
            let Some(t) = self.next() else {
                self.error(
                    off,
                    format!("unterminated {kw} block: expected \"}}\" before the end of the file"),
                );
                return None;
            };
            let w = self.text(t);
            let c = self.comments_here();
            let twice = |seen: bool, p: &mut Self| {
                if seen {
                    p.error(t.start, format!("\"{w}\" is given twice in {kw}"));
                }
                seen
            };
            let field: &'static str = match (t.kind, w) {
                (TokKind::Close, _) => {
                    comments.end.extend(c);
                    break;
                }
                (TokKind::Word, "Transform") => {
                    if twice(transform.is_some(), self) {
                        ok = false;
                    }
                    offsets.push(("Transform", t.start));
                    let (ops, at) = self.parse_texture_transform(&mut comments)?;
                    transform = Some(ops);
                    op_offsets = at;
                    "Transform"
                }
                (TokKind::Word, "materialIndex") => {
                    let (n, at) = self.expect_count(w)?;
                    if indices.len() == 2 {
                        self.error(
                            t.start,
                            format!("a {kw} takes two materialIndex lines; this is a third"),
                        );
                        ok = false;
                    }
                    match u32::try_from(n) {
                        Ok(n) => indices.push((n, at)),
                        Err(_) => {
                            self.error(at, format!("materialIndex {n} is out of range"));
                            ok = false;
                        }
                    }
                    if indices.len() == 2 {
                        "materialIndex#2"
                    } else {
                        "materialIndex"
                    }
                }
                (TokKind::Word, "octaves") if kind.has_octaves() => {
                    let (n, at) = self.expect_count(w)?;
                    if twice(octaves.is_some(), self) {
                        ok = false;
                    }
                    offsets.push(("octaves", at));
                    octaves = Some(u32::try_from(n).unwrap_or(u32::MAX));
                    "octaves"
                }
                (TokKind::Word, name @ ("frequency" | "amplitude")) if kind.has_waves() => {
                    let k = usize::from(name == "amplitude");
                    let v = self.expect_numbers(w, 1)?;
                    if twice(waves[k].is_some(), self) {
                        ok = false;
                    }
                    offsets.push((if k == 0 { "frequency" } else { "amplitude" }, t.start));
                    waves[k] = v.first().copied();
                    if k == 0 { "frequency" } else { "amplitude" }
                }
                _ => {
                    let (found, at) = self.describe(Some(t));
                    self.error(
                        at,
                        format!("unexpected {found} in {kw} (expected {expected})"),
                    );
                    if t.kind == TokKind::Open {
                        self.skip_block();
                    } else if self.peek().is_some_and(|n| n.kind == TokKind::Open) {
                        self.pos += 1;
                        self.skip_block();
                    } else {
                        // A field of some other block: its numbers go with it.
                        while self
                            .peek()
                            .is_some_and(|n| n.kind == TokKind::Word && is_numberlike(self.text(n)))
                        {
                            self.pos += 1;
                        }
                    }
                    ok = false;
                    continue;
                }
            };
            if !c.is_empty() {
                comments
                    .inner
                    .entry(Anchor::Field(field.into()))
                    .or_default()
                    .extend(c);
            }
        }
        let mut missing = Vec::new();
        if indices.len() < 2 {
            missing.push(format!("two materialIndex lines (found {})", indices.len()));
        }
        if kind.has_octaves() && octaves.is_none() {
            missing.push("octaves".into());
        }
        for (name, v) in ["frequency", "amplitude"].iter().zip(waves) {
            if kind.has_waves() && v.is_none() {
                missing.push((*name).into());
            }
        }
        if !missing.is_empty() {
            self.error(off, format!("{kw} needs {}", missing.join(", ")));
            return None;
        }
        if !ok {
            return None;
        }
        let texture = SolidTexture {
            kind,
            transform,
            materials: [indices[0].0, indices[1].0],
            octaves: octaves.unwrap_or(0),
            frequency: waves[0].unwrap_or(0.0),
            amplitude: waves[1].unwrap_or(0.0),
        };
        if let Err(e) = validate::check_texture(&texture) {
            let at =
                e.op.and_then(|i| op_offsets.get(i).copied())
                    .or_else(|| {
                        offsets
                            .iter()
                            .find(|(f, _)| *f == e.field.name())
                            .map(|x| x.1)
                    })
                    .unwrap_or(off);
            self.error(at, format!("{kw}: {}", e.message));
            return None;
        }
        self.texture_refs.push(TextureRefs {
            material: self.materials.len(),
            at: [indices[0].1, indices[1].1],
        });
        Some(Material {
            comments,
            ..Material::textured(texture)
        })
    }

    /// A texture's `Transform { ops }` after its keyword: the ops and where each stands.
    /// Comments before an op are kept at that op; those before its `}` go to the
    /// texture's end.
    fn parse_texture_transform(
        &mut self,
        comments: &mut Comments,
    ) -> Option<(Vec<crate::scene::TransformOp>, Vec<usize>)> {
        let open = self.expect_open("Transform")?;
        let mut ops = Vec::new();
        let mut at = Vec::new();
        loop {
            let Some(t) = self.next() else {
                self.error(
                    open,
                    "unterminated Transform block: expected \"}\" before the end of the file",
                );
                return None;
            };
            let c = self.comments_here();
            match t.kind {
                TokKind::Close => {
                    comments.end.extend(c);
                    return Some((ops, at));
                }
                TokKind::Word => {
                    let w = self.text(t);
                    let op = self.parse_op(w, t.start)?;
                    if !c.is_empty() {
                        comments
                            .inner
                            .entry(Anchor::Op(ops.len()))
                            .or_default()
                            .extend(c);
                    }
                    ops.push(op);
                    at.push(t.start);
                }
                TokKind::Open => {
                    self.error(t.start, "unexpected \"{\" in a texture's Transform");
                    self.skip_block();
                    return None;
                }
            }
        }
    }
}
