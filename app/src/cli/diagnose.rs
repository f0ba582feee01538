//! Which known mistake a student's images are: each catalogue mistake that can change this
//! scene's picture (core's `render::mistakes`) is rendered as tracelab's own variant and the
//! student's images judged against it by the same criterion as the reference; when no single
//! mistake explains them, pairs of the mistakes that explain part of them are tried.

use rayon::prelude::*;
use tracelab_core::render::mistakes::{
    Mistake, Variant, Views, render_variant, scene_with, variant_rgb8,
};
use tracelab_core::{CompiledScene, RenderSettings, Scene, View};

use super::judge::{Criterion, count, explained, off};

/// One of the student's images of the right size, with its reference's bytes.
pub struct Judged<'a> {
    pub what: &'static str,
    pub view: View,
    pub depth: (f32, f32),
    pub mine: &'a [u8],
    pub reference: &'a [u8],
}

/// A variant judged against the student's images: it matches when every image that fails
/// against the reference matches it.
#[derive(Clone, Debug)]
pub struct Candidate {
    pub variant: Variant,
    /// Per image: pixels off against the variant.
    pub off: Vec<usize>,
    /// Per image: pixels off against the reference that the variant explains.
    pub explained: Vec<usize>,
    pub matches: bool,
}

impl Candidate {
    fn explained_total(&self) -> usize {
        self.explained.iter().sum()
    }
    fn off_total(&self) -> usize {
        self.off.iter().sum()
    }
}

/// What the catalogue says about the student's images.
#[derive(Debug)]
pub struct Diagnosis {
    /// Mistakes that change this picture beyond the tolerance (the others were not counted).
    pub tried: Vec<Mistake>,
    /// Variants the images match, best (fewest pixels off) first: singles, or else pairs.
    pub found: Vec<Candidate>,
    /// With nothing found, the single mistake that explains the most.
    pub closest: Option<Candidate>,
    /// Per image, pixels off against the reference.
    pub off_reference: Vec<usize>,
    pub pairs_tried: usize,
}

/// How many of the partly explaining mistakes are paired (15 pairs at most).
const PAIRED: usize = 6;

/// Mistakes that cannot be made at once (two rules for the same term).
fn exclusive(a: Mistake, b: Mistake) -> bool {
    use Mistake::*;
    matches!(
        (a.min(b), a.max(b)),
        (BackFacesLit, BackFacesFlippedWithoutShadeBack)
            | (AmbientNotTimesDiffuse, AmbientTimesDiffuseTwice)
    )
}

/// The variant's bytes for each image, or `None` when it changes no pixel of any of them
/// beyond the tolerance (the mistake does not show in this picture).
fn variant_images(
    scene: &Scene,
    compiled: &CompiledScene,
    settings: &RenderSettings,
    variant: Variant,
    images: &[Judged],
    tolerance: u8,
) -> Option<Vec<Vec<u8>>> {
    let own;
    let compiled = if variant.changes_scene() {
        own = CompiledScene::new(&scene_with(scene, variant)?);
        &own
    } else {
        compiled
    };
    let s = RenderSettings {
        variant: Some(variant),
        ..*settings
    };
    let frame = render_variant(compiled, &s);
    let out: Vec<Vec<u8>> = images
        .iter()
        .map(|j| variant_rgb8(compiled, &frame, Some(variant), j.view, j.depth))
        .collect();
    let changes = out
        .iter()
        .zip(images)
        .any(|(v, j)| off(v, j.reference, tolerance) > 0);
    changes.then_some(out)
}

fn judge(variant: Variant, bytes: &[Vec<u8>], images: &[Judged], c: &Criterion) -> Candidate {
    let mut cand = Candidate {
        variant,
        off: Vec::new(),
        explained: Vec::new(),
        matches: true,
    };
    for (v, j) in bytes.iter().zip(images) {
        let o = off(j.mine, v, c.tolerance);
        let total = j.mine.len() / 3;
        // Only the images that fail need explaining: a program may keep one rule right in one
        // image and wrong in another (the right t for occlusion, the object-space t as depth).
        let fails = !c.matches(off(j.mine, j.reference, c.tolerance), total);
        cand.matches &= !fails || c.matches(o, total);
        cand.off.push(o);
        cand.explained
            .push(explained(j.mine, j.reference, v, c.tolerance));
    }
    cand
}

fn best_first(v: &mut [Candidate]) {
    v.sort_by_key(|c| (c.off_total(), std::cmp::Reverse(c.explained_total())));
}

pub fn diagnose(
    scene: &Scene,
    compiled: &CompiledScene,
    settings: &RenderSettings,
    images: &[Judged],
    c: &Criterion,
) -> Diagnosis {
    let views = Views {
        color: images.iter().any(|j| j.view == View::Color),
        normals: images.iter().any(|j| j.view == View::Normals),
        depth: images.iter().any(|j| j.view == View::Depth),
    };
    let off_reference = images
        .iter()
        .map(|j| off(j.mine, j.reference, c.tolerance))
        .collect();
    let cheap: Vec<Mistake> = Mistake::ALL
        .into_iter()
        .filter(|m| m.may_change(scene, compiled, settings, views))
        .collect();
    let singles: Vec<(Mistake, Candidate)> = cheap
        .par_iter()
        .filter_map(|&m| {
            let v = Variant::one(m);
            let bytes = variant_images(scene, compiled, settings, v, images, c.tolerance)?;
            Some((m, judge(v, &bytes, images, c)))
        })
        .collect();
    let tried: Vec<Mistake> = singles.iter().map(|(m, _)| *m).collect();
    let mut found: Vec<Candidate> = singles
        .iter()
        .filter(|(_, k)| k.matches)
        .map(|(_, k)| k.clone())
        .collect();
    let mut pairs_tried = 0;
    if found.is_empty() {
        let mut partial: Vec<&(Mistake, Candidate)> = singles
            .iter()
            .filter(|(_, k)| k.explained_total() > 0)
            .collect();
        partial.sort_by_key(|(m, k)| (std::cmp::Reverse(k.explained_total()), *m));
        partial.truncate(PAIRED);
        let pairs: Vec<Variant> = partial
            .iter()
            .enumerate()
            .flat_map(|(i, (a, _))| partial[i + 1..].iter().map(move |(b, _)| (*a, *b)))
            .filter(|&(a, b)| !exclusive(a, b))
            .map(|(a, b)| Variant::pair(a, b))
            .collect();
        pairs_tried = pairs.len();
        found = pairs
            .par_iter()
            .filter_map(|&v| {
                let bytes = variant_images(scene, compiled, settings, v, images, c.tolerance)?;
                let k = judge(v, &bytes, images, c);
                k.matches.then_some(k)
            })
            .collect();
    }
    best_first(&mut found);
    let closest = if found.is_empty() {
        singles
            .iter()
            .filter(|(_, k)| k.explained_total() > 0)
            .max_by_key(|(m, k)| (k.explained_total(), std::cmp::Reverse(*m)))
            .map(|(_, k)| k.clone())
    } else {
        None
    };
    Diagnosis {
        tried,
        found,
        closest,
        off_reference,
        pairs_tried,
    }
}

fn names(v: Variant) -> String {
    v.mistakes()
        .map(Mistake::name)
        .collect::<Vec<_>>()
        .join(" + ")
}

/// "412 of the 412 pixels off (colour 400 of 400, depth 12 of 12)".
fn explains(k: &Candidate, d: &Diagnosis, images: &[Judged]) -> String {
    let total: usize = d.off_reference.iter().sum();
    let per: Vec<String> = images
        .iter()
        .zip(&k.explained)
        .zip(&d.off_reference)
        .filter(|(_, o)| **o > 0)
        .map(|((j, e), o)| format!("{} {} of {}", j.what, count(*e), count(*o)))
        .collect();
    format!(
        "{} of the {} pixels off ({})",
        count(k.explained_total()),
        count(total),
        per.join(", ")
    )
}

/// The diagnosis as text: what matches first, then what it explains and the rule.
pub fn diagnosis_text(d: &Diagnosis, images: &[Judged]) -> String {
    let mut out = String::new();
    if let Some(best) = d.found.first() {
        let ms: Vec<Mistake> = best.variant.mistakes().collect();
        if ms.len() == 1 {
            out.push_str(&format!(
                "diagnosis: your images match tracelab's render with one known mistake: {} ({})\n",
                ms[0].explanation(),
                ms[0].name()
            ));
        } else {
            let what: Vec<String> = ms
                .iter()
                .map(|m| format!("{} ({})", m.explanation(), m.name()))
                .collect();
            out.push_str(&format!(
                "diagnosis: your images match tracelab's render with two known mistakes at once: {}\n",
                what.join("; and ")
            ));
        }
        for m in &ms {
            out.push_str(&format!("  the course's rule: {}\n", m.rule()));
        }
        out.push_str(&format!("  it explains {}\n", explains(best, d, images)));
        if d.found.len() > 1 {
            let others: Vec<String> = d.found[1..].iter().map(|k| names(k.variant)).collect();
            out.push_str(&format!(
                "  also consistent with: {} (more pixels off)\n",
                others.join(", ")
            ));
        }
        return out;
    }
    if d.tried.is_empty() {
        out.push_str(
            "diagnosis: no known mistake changes this picture, so none explains your images\n",
        );
        return out;
    }
    let tried: Vec<&str> = d.tried.iter().map(|m| m.name()).collect();
    out.push_str(&format!(
        "diagnosis: none of the {} known mistakes that change this picture explains your images, alone or in pairs ({} pairs tried): {}\n",
        d.tried.len(),
        d.pairs_tried,
        tried.join(", ")
    ));
    if let Some(k) = &d.closest {
        out.push_str(&format!(
            "  the closest, {} ({}), explains {}\n",
            names(k.variant),
            k.variant
                .mistakes()
                .map(Mistake::explanation)
                .collect::<Vec<_>>()
                .join("; "),
            explains(k, d, images)
        ));
    }
    out
}
