//! Assignments 3 and 4: Blinn–Phong highlights, point lights, shadow rays, mirror reflection
//! and refraction, as `../shared/mit6837-semester/AGREEMENT.md` writes the course's rules:
//!
//! c = c_a·k_d + Σ_lights c_l·(k_d·max(N·L, 0) + k_s·(N·H)^e) + k_r·trace(r) + k_t·trace(t)
//!
//! with H = normalize(L − d) (the Blinn half vector), the specular term 0 where N·L ≤ 0 (or,
//! with the optional fix, multiplied by max(N·L, 0)), a light's terms dropped where a shadow
//! ray meets anything before it (transparent objects block too; ambient stays), a point
//! light's colour divided by c + l·d + q·d², r = d − 2(N·d)N, t by Snell's law entering where
//! N·d < 0 and leaving (index inverted, normal flipped) where N·d > 0, nothing transmitted on
//! total internal reflection, `-bounces` levels of secondary rays, a ray whose weight is below
//! `-weight` not traced, and a secondary ray that meets nothing giving the background.
//!
//! A scene with only diffuse materials, directional lights and no shadows never comes here:
//! it keeps `shade.rs`'s fast path, bit for bit. The diffuse sum below is written in the
//! same order as there, so a Phong scene's diffuse part is the same number too.

use glam::Vec3;

use super::RenderSettings;
use super::compile::{CompiledScene, Hit};
use super::grid_data::RayCounts;
use super::rules::{Ambient, Rules};
use crate::geometry::Ray;
use crate::scene::Phong;

/// How far along a secondary or shadow ray a surface must be to count: keeps a ray from
/// meeting the surface it leaves (shadow acne). The course's programs use 1e-5 to 1e-3; the
/// references do not depend on the choice within their tolerance.
pub const SECONDARY_T_MIN: f32 = 1e-4;

/// How far a shadow ray's origin is lifted off the surface along the normal, relative to the
/// point's largest coordinate (at least 1): a few thousand ulps of it.
const SHADOW_LIFT: f32 = 1e-4;

/// Assignment 4's rays beyond the eye ray and assignment 3's optional specular fix: the
/// course's `-shadows`, `-bounces N`, `-weight W`, and tracelab's `-specular_fix`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Secondary {
    pub shadows: bool,
    /// Levels of reflected and refracted rays after the eye ray (0: none).
    pub bounces: u32,
    /// A secondary ray whose weight (the product of the colours it is seen through, as a
    /// length) is below this is not traced.
    pub weight: f32,
    /// The handout's optional fix: the highlight fades with max(N·L, 0) instead of stopping
    /// where N·L ≤ 0.
    pub specular_fix: bool,
    /// How shadow rays are asked (the same answer either way; for `bench-progressive`).
    pub shadow_query: ShadowQuery,
}

/// How a shadow ray asks whether anything lies before the light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShadowQuery {
    /// `CompiledScene::occluded`: stops at the first blocker found.
    #[default]
    AnyHit,
    /// The closest hit, then its t compared: what the any-hit query saves is measured
    /// against this.
    ClosestHit,
}

/// The most levels `-bounces` takes: deeper than any course scene needs (10), and shallow
/// enough that the recursion stays well inside a thread's stack.
pub const MAX_BOUNCES: u32 = 100;

impl Default for Secondary {
    fn default() -> Self {
        Secondary::NONE
    }
}

/// The most secondary rays (reflected and refracted) one eye ray may lead to. A material
/// that both reflects and refracts doubles the rays at every level, so `-bounces 40` would
/// never finish; 65,536 allows `-bounces 15` there (the course's scenes use at most 5) and
/// any count up to the cap of 100 where rays do not branch.
pub const MAX_SECONDARY_RAYS: f64 = 65536.0;

impl Secondary {
    /// The course's defaults: no shadows, no bounces, every ray traced, no fix (a const, for
    /// tables of settings such as the editor's Lecture figures).
    pub const NONE: Secondary = Secondary {
        shadows: false,
        bounces: 0,
        weight: 0.0,
        specular_fix: false,
        shadow_query: ShadowQuery::AnyHit,
    };

    /// The command line's `-bounces` and `-weight` checked: at most [`MAX_BOUNCES`] levels, a
    /// weight that is a number of 0 or more. The message names the flag as `flag` spells it.
    pub fn check_flags(&self, bounces_flag: &str, weight_flag: &str) -> Result<(), String> {
        if self.bounces > MAX_BOUNCES {
            return Err(format!(
                "{bounces_flag}: at most {MAX_BOUNCES} levels, found {}",
                self.bounces
            ));
        }
        if !(self.weight.is_finite() && self.weight >= 0.0) {
            return Err(format!(
                "{weight_flag}: expected a number of 0 or more, found {}",
                self.weight
            ));
        }
        Ok(())
    }

    /// An upper bound on the reflected and refracted rays one eye ray leads to in `scene`
    /// (shadow rays aside: one per light at each of these): Σ b^k for k = 1..=bounces, b the
    /// most secondary rays one material spawns (0, 1 or 2).
    pub fn worst_secondary_rays(&self, scene: &CompiledScene) -> f64 {
        let b = scene
            .phong
            .iter()
            .map(|p| u32::from(p.reflective != Vec3::ZERO) + u32::from(p.transparent != Vec3::ZERO))
            .max()
            .unwrap_or(0);
        let b = f64::from(b);
        let (mut sum, mut level) = (0.0, 1.0);
        for _ in 0..self.bounces {
            level *= b;
            sum += level;
        }
        sum
    }

    /// Refuses settings whose rays would grow past [`MAX_SECONDARY_RAYS`] a pixel in `scene`,
    /// saying why.
    pub fn check_bounded(&self, scene: &CompiledScene) -> Result<(), String> {
        self.check_bounded_as(scene, "-bounces")
    }

    /// [`Self::check_bounded`], the message naming the bounce count as `bounces_flag`.
    pub fn check_bounded_as(
        &self,
        scene: &CompiledScene,
        bounces_flag: &str,
    ) -> Result<(), String> {
        let worst = self.worst_secondary_rays(scene);
        if worst <= MAX_SECONDARY_RAYS {
            return Ok(());
        }
        let mut most = self.bounces;
        while most > 0
            && (Secondary {
                bounces: most,
                ..*self
            })
            .worst_secondary_rays(scene)
                > MAX_SECONDARY_RAYS
        {
            most -= 1;
        }
        let worst = if worst < 1e12 {
            format!("{worst:.0}")
        } else {
            format!("about {worst:.1e}")
        };
        Err(format!(
            "{bounces_flag} {}: a material of this scene both reflects and refracts, so one \
             pixel could trace up to {worst} secondary rays; at most {MAX_SECONDARY_RAYS:.0} \
             are allowed ({bounces_flag} {most} or fewer here)",
            self.bounces
        ))
    }
}

/// Whether a render of `scene` with these settings needs this module (anything beyond the
/// lecture's diffuse shading).
#[inline]
pub fn needs_whitted(scene: &CompiledScene, s: &RenderSettings) -> bool {
    scene.has_phong_terms || !scene.point_lights.is_empty() || s.secondary.shadows
}

/// An eye ray's colour and world normal (the normal view's), as `shade_fast` gives them.
pub(super) fn shade_primary(
    scene: &CompiledScene,
    ray: &Ray,
    hit: &Hit,
    s: &RenderSettings,
) -> (Vec3, Vec3) {
    let at_hit = scene.ray_for_hit_point(ray, hit, s.object_rays);
    let normal = scene.world_normal(&at_hit, hit, s.normal_transform);
    let c = color_at(
        scene,
        &at_hit,
        hit,
        normal,
        (s, &Rules::COURSE),
        s.secondary.bounces,
        1.0,
        &mut NoRecord,
    );
    (c, normal)
}

/// An eye ray's colour under `rules` (the mistake catalogue's variants): `at_hit` the ray
/// whose `at(hit.t)` is the hit point, `normal` the world normal the variant computed.
pub(super) fn shade_with_rules(
    scene: &CompiledScene,
    at_hit: &Ray,
    hit: &Hit,
    normal: Vec3,
    s: &RenderSettings,
    rules: &Rules,
) -> Vec3 {
    color_at(
        scene,
        at_hit,
        hit,
        normal,
        (s, rules),
        s.secondary.bounces,
        1.0,
        &mut NoRecord,
    )
}

/// An eye ray's whole ray tree: every shadow, reflected and refracted ray the render traces
/// for it, with what each brings back (the pixel inspector's and `inspect`'s view of it).
/// The same code as the render runs, recording as it goes: the root's colour is the
/// pixel's, bit for bit.
pub fn ray_tree(scene: &CompiledScene, ray: &Ray, s: &RenderSettings) -> RayNode {
    let mut root = RayNode::new(RayKind::Eye, *ray, 1.0, Vec3::ONE);
    match scene.intersect(ray, scene.camera.t_min(), f32::INFINITY) {
        None => {
            root.color = scene.background;
        }
        Some(hit) => {
            let at_hit = scene.ray_for_hit_point(ray, &hit, s.object_rays);
            let normal = scene.world_normal(&at_hit, &hit, s.normal_transform);
            root.hit(scene, &at_hit, &hit, normal);
            root.color = color_at(
                scene,
                &at_hit,
                &hit,
                normal,
                (s, &Rules::COURSE),
                s.secondary.bounces,
                1.0,
                &mut root,
            );
        }
    }
    root
}

/// Why a ray of the tree was not traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cut {
    /// `-bounces` levels were used up.
    Bounces,
    /// Its weight was below `-weight`.
    Weight { weight: f32 },
    /// Past the critical angle: nothing is transmitted.
    TotalInternalReflection,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    Eye,
    Reflected,
    Refracted,
}

/// One shadow ray: from the hit point toward light `light` (its index in the scene's
/// Lights), and what blocked it.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowRay {
    pub light: usize,
    pub ray: Ray,
    /// Distance to the light (infinite for a directional one).
    pub distance: f32,
    /// The nearest blocker: its t along the shadow ray and its scene node.
    pub blocker: Option<Blocker>,
}

/// What stopped a shadow ray: t along it and the scene node hit.
pub type Blocker = (f32, Option<crate::scene::NodeId>);

/// One light's diffuse and specular share at a hit (zero in shadow or from behind).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightShare {
    pub light: usize,
    pub color: Vec3,
}

/// One ray of a pixel's ray tree.
#[derive(Clone, Debug, PartialEq)]
pub struct RayNode {
    pub kind: RayKind,
    pub ray: Ray,
    /// The product of the colours this ray is seen through, as a length (the eye ray's is 1).
    pub weight: f32,
    /// The material colour its result is multiplied by (reflective or transparent; 1 for
    /// the eye ray).
    pub factor: Vec3,
    /// t of the hit, the scene node hit, the world point and the shading normal's rule's
    /// world normal; None for a miss (the ray brings back the background).
    pub hit: Option<(f32, Option<crate::scene::NodeId>, Vec3, Vec3)>,
    /// The ambient term c_a·k_d.
    pub ambient: Vec3,
    pub lights: Vec<LightShare>,
    pub shadows: Vec<ShadowRay>,
    pub children: Vec<RayNode>,
    /// Secondary rays not traced, and why.
    pub cuts: Vec<(RayKind, Cut)>,
    /// What this ray brings back, before `factor`.
    pub color: Vec3,
}

impl RayNode {
    fn new(kind: RayKind, ray: Ray, weight: f32, factor: Vec3) -> Self {
        RayNode {
            kind,
            ray,
            weight,
            factor,
            hit: None,
            ambient: Vec3::ZERO,
            lights: Vec::new(),
            shadows: Vec::new(),
            children: Vec::new(),
            cuts: Vec::new(),
            color: Vec3::ZERO,
        }
    }

    fn hit(&mut self, scene: &CompiledScene, ray: &Ray, hit: &Hit, normal: Vec3) {
        self.hit = Some((hit.t, scene.hit_node(hit), ray.at(hit.t), normal));
    }

    /// Rays in the tree, this one included.
    pub fn count(&self) -> usize {
        1 + self.shadows.len() + self.children.iter().map(RayNode::count).sum::<usize>()
    }
}

/// What the shading code tells whoever records it; the render's [`NoRecord`] compiles to
/// nothing.
trait Record {
    fn ambient(&mut self, _c: Vec3) {}
    fn shadow(&mut self, _light: usize, _ray: &Ray, _distance: f32, _blocker: Option<Blocker>) {}
    fn light(&mut self, _light: usize, _c: Vec3) {}
    fn cut(&mut self, _kind: RayKind, _why: Cut) {}
    /// A secondary ray about to be traced: the recorder to hand it.
    fn child(&mut self, kind: RayKind, ray: &Ray, weight: f32, factor: Vec3) -> &mut Self;
    fn hit(&mut self, _scene: &CompiledScene, _ray: &Ray, _hit: &Hit, _normal: Vec3) {}
    fn color(&mut self, _c: Vec3) {}
    /// Whether shadow rays must find their blocker (the tree names it), not just any.
    const WANTS_BLOCKER: bool = false;
}

struct NoRecord;

impl Record for NoRecord {
    #[inline(always)]
    fn child(&mut self, _: RayKind, _: &Ray, _: f32, _: Vec3) -> &mut Self {
        self
    }
}

impl Record for RayNode {
    const WANTS_BLOCKER: bool = true;
    fn ambient(&mut self, c: Vec3) {
        self.ambient = c;
    }
    fn shadow(&mut self, light: usize, ray: &Ray, distance: f32, blocker: Option<Blocker>) {
        self.shadows.push(ShadowRay {
            light,
            ray: *ray,
            distance,
            blocker,
        });
    }
    fn light(&mut self, light: usize, color: Vec3) {
        self.lights.push(LightShare { light, color });
    }
    fn cut(&mut self, kind: RayKind, why: Cut) {
        self.cuts.push((kind, why));
    }
    fn child(&mut self, kind: RayKind, ray: &Ray, weight: f32, factor: Vec3) -> &mut Self {
        self.children.push(RayNode::new(kind, *ray, weight, factor));
        let last = self.children.len() - 1;
        &mut self.children[last]
    }
    fn hit(&mut self, scene: &CompiledScene, ray: &Ray, hit: &Hit, normal: Vec3) {
        RayNode::hit(self, scene, ray, hit, normal);
    }
    fn color(&mut self, c: Vec3) {
        self.color = c;
    }
}

/// The colour a secondary ray brings back: the background where it meets nothing.
fn trace<R: Record>(
    scene: &CompiledScene,
    ray: &Ray,
    bounces: u32,
    weight: f32,
    (s, rules): (&RenderSettings, &Rules),
    rec: &mut R,
) -> Vec3 {
    if let Some(g) = scene.grid() {
        RayCounts::add(&g.stats.secondary_rays, 1);
    }
    let c = match scene.intersect(ray, SECONDARY_T_MIN, f32::INFINITY) {
        None => scene.background,
        Some(hit) => {
            let normal = scene.world_normal(ray, &hit, s.normal_transform);
            rec.hit(scene, ray, &hit, normal);
            color_at(scene, ray, &hit, normal, (s, rules), bounces, weight, rec)
        }
    };
    rec.color(c);
    c
}

/// The colour at a hit with world normal `normal`; `bounces` levels of secondary rays left.
#[allow(clippy::too_many_arguments)]
fn color_at<R: Record>(
    scene: &CompiledScene,
    ray: &Ray,
    hit: &Hit,
    normal: Vec3,
    (s, rules): (&RenderSettings, &Rules),
    bounces: u32,
    weight: f32,
    rec: &mut R,
) -> Vec3 {
    let p = ray.at(hit.t);
    // A solid texture is evaluated at the world point (its Transform takes it from there).
    let (kd, m) = scene.hit_shading(hit, p);
    let mut n = normal;
    let back = ray.direction.dot(normal) > 0.0;
    let absolute = back && s.shade_back && rules.shade_back_absolute;
    if back && !absolute {
        if s.shade_back || rules.back_faces_flipped {
            n = -normal;
        } else if !rules.back_faces_lit {
            // As in assignment 2: a back face is black without -shade_back.
            return Vec3::ZERO;
        }
    }
    let d = ray.direction.normalize_or_zero();
    let ambient = match rules.ambient {
        Ambient::TimesDiffuse => scene.ambient * kd,
        Ambient::Plain => scene.ambient,
        Ambient::TimesDiffuseTwice => scene.ambient * kd * kd,
    };
    // The mistake adds the ambient term last, once it knows whether a light was blocked.
    let mut c = if rules.ambient_dropped_in_shadow {
        Vec3::ZERO
    } else {
        ambient
    };
    rec.ambient(ambient);
    let at = Surface {
        p,
        n,
        d,
        kd,
        m: &m,
        absolute,
    };
    let mut shadowed = false;
    for (k, &(l, color)) in scene.lights.iter().enumerate() {
        let i = scene.light_index(k);
        let (share, blocked) =
            light_term(scene, &at, (i, l, color, f32::INFINITY), (s, rules), rec);
        c += share;
        shadowed |= blocked;
    }
    for (k, pl) in scene.point_lights.iter().enumerate() {
        let i = scene.light_index(scene.lights.len() + k);
        let to = pl.position - p;
        let dist = to.length();
        let Some(l) = (dist > 0.0).then(|| to / dist) else {
            continue;
        };
        let a = pl.attenuation;
        let color = pl.color / (a.x + a.y * dist + a.z * dist * dist);
        let (share, blocked) = light_term(scene, &at, (i, l, color, dist), (s, rules), rec);
        c += share;
        shadowed |= blocked;
    }
    if rules.ambient_dropped_in_shadow && !shadowed {
        c += ambient;
    }
    for (kind, factor) in [
        (RayKind::Reflected, m.reflective),
        (RayKind::Refracted, m.transparent),
    ] {
        if factor == Vec3::ZERO {
            continue;
        }
        if bounces == 0 {
            rec.cut(kind, Cut::Bounces);
            continue;
        }
        let w = weight * factor.length();
        if w < s.secondary.weight && !rules.weight_ignored {
            rec.cut(kind, Cut::Weight { weight: w });
            continue;
        }
        let dir = if kind == RayKind::Reflected {
            Some((d - 2.0 * n.dot(d) * n).normalize_or_zero())
        } else {
            // Entering or leaving by the side the ray meets, whatever shade-back did to n.
            let (outward, n_i, n_t) = if d.dot(normal) < 0.0 {
                (normal, 1.0, m.index_of_refraction)
            } else if rules.index_not_inverted {
                (-normal, 1.0, m.index_of_refraction)
            } else {
                (-normal, m.index_of_refraction, 1.0)
            };
            transmitted(outward, d, n_i, n_t).or_else(|| {
                rules
                    .tir_transmits_reflected
                    .then(|| (d - 2.0 * outward.dot(d) * outward).normalize_or_zero())
            })
        };
        let Some(dir) = dir else {
            rec.cut(kind, Cut::TotalInternalReflection);
            continue;
        };
        let next = Ray::new(p, dir);
        let child = rec.child(kind, &next, w, factor);
        c += factor * trace(scene, &next, bounces - 1, w, (s, rules), child);
    }
    c
}

/// Where a light's share is computed: the point, the normal facing the ray, the ray's unit
/// direction, the diffuse colour and the Phong terms.
struct Surface<'a> {
    p: Vec3,
    n: Vec3,
    d: Vec3,
    kd: Vec3,
    m: &'a Phong,
    /// -shade_back's |L·N| mistake on a back face.
    absolute: bool,
}

/// One light's diffuse and specular share at `at`: (its index, unit direction toward it, its
/// colour there, distance to it — infinite for a directional light); zero in its shadow.
/// Also whether a shadow ray was blocked.
#[inline]
fn light_term<R: Record>(
    scene: &CompiledScene,
    at: &Surface,
    (i, l, color, dist): (usize, Vec3, Vec3, f32),
    (s, rules): (&RenderSettings, &Rules),
    rec: &mut R,
) -> (Vec3, bool) {
    let Surface {
        p,
        n,
        d,
        kd,
        m,
        absolute,
    } = *at;
    let nl = if absolute { l.dot(n).abs() } else { l.dot(n) };
    let behind_highlight = rules.specular_behind && m.specular != Vec3::ZERO;
    // Nothing lights a point from behind its surface, so no shadow ray is needed there.
    if nl <= 0.0 && !behind_highlight {
        rec.light(i, Vec3::ZERO);
        return (Vec3::ZERO, false);
    }
    if s.secondary.shadows {
        if let Some(g) = scene.grid() {
            RayCounts::add(&g.stats.shadow_rays, 1);
        }
        // Lifted off the surface along its normal as well as started past t_min: a point
        // computed a hair inside a curved surface would otherwise meet it again at a
        // grazing angle, farther than any t_min (acne at the terminator of a scaled sphere).
        let lift = if rules.shadow_t_min_zero {
            // The mistake is no epsilon at all.
            Vec3::ZERO
        } else {
            n * SHADOW_LIFT * p.abs().max_element().max(1.0)
        };
        let shadow = Ray::new(p + lift, l);
        let t_min = if rules.shadow_t_min_zero {
            0.0
        } else {
            SECONDARY_T_MIN
        };
        let blocked = if R::WANTS_BLOCKER {
            let b = scene.intersect(&shadow, t_min, dist);
            rec.shadow(i, &shadow, dist, b.map(|h| (h.t, scene.hit_node(&h))));
            b.is_some()
        } else if rules.transparent_casts_no_shadow {
            opaque_blocker(scene, &shadow, t_min, dist)
        } else {
            blocked(scene, &shadow, t_min, dist, s.secondary.shadow_query)
        };
        if blocked {
            rec.light(i, Vec3::ZERO);
            return (Vec3::ZERO, true);
        }
    }
    // The same operations, in the same order, as `shade.rs`'s diffuse term.
    let mut c = nl.max(0.0) * color * kd;
    if m.specular != Vec3::ZERO {
        let highlight = if rules.reflection_vector {
            // Phong: the light's mirror direction against the direction to the eye.
            let r = 2.0 * n.dot(l) * n - l;
            r.dot(-d).max(0.0).powf(m.exponent)
        } else {
            let h = (l - d).normalize_or_zero();
            n.dot(h).max(0.0).powf(m.exponent)
        };
        let spec = if s.secondary.specular_fix {
            // nl > 0 here unless a mistake keeps the highlight behind the surface.
            m.specular * highlight * nl.max(0.0)
        } else {
            m.specular * highlight
        };
        c += color * spec;
    }
    rec.light(i, c);
    (c, false)
}

/// Whether anything lies on the shadow ray before the light: the any-hit query, which stops
/// at the first blocker it finds (the same answer as a closest hit, tested bit for bit).
#[inline]
fn blocked(scene: &CompiledScene, shadow: &Ray, t_min: f32, dist: f32, query: ShadowQuery) -> bool {
    match query {
        ShadowQuery::AnyHit => scene.occluded(shadow, t_min, dist),
        ShadowQuery::ClosestHit => scene.intersect(shadow, t_min, dist).is_some(),
    }
}

/// The most transparent surfaces a shadow ray of the no-transparent-shadow mistake steps
/// through before it counts as unblocked (a guard against a degenerate loop).
const MAX_TRANSPARENT_STEPS: usize = 64;

/// Whether an opaque object lies on the shadow ray before the light, stepping through
/// transparent ones (the mistake `transparent-casts-no-shadow`; the course's shadow rays stop
/// at anything).
fn opaque_blocker(scene: &CompiledScene, shadow: &Ray, t_min: f32, dist: f32) -> bool {
    let mut from = t_min;
    for _ in 0..MAX_TRANSPARENT_STEPS {
        let Some(h) = scene.intersect(shadow, from, dist) else {
            return false;
        };
        if scene.hit_shading(&h, shadow.at(h.t)).1.transparent == Vec3::ZERO {
            return true;
        }
        from = h.t + SECONDARY_T_MIN;
    }
    false
}

/// The handout's `transmittedDirection`: `d` (unit) crossing from index `n_i` into `n_t`
/// through a surface whose unit normal `n` faces the incoming ray; None on total internal
/// reflection.
pub fn transmitted(n: Vec3, d: Vec3, n_i: f32, n_t: f32) -> Option<Vec3> {
    let eta = n_i / n_t;
    let cos_i = -n.dot(d);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    Some((eta * d + (eta * cos_i - k.sqrt()) * n).normalize_or_zero())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refraction_bends_toward_the_normal_entering_and_reflects_totally_past_the_critical_angle() {
        let n = Vec3::Y;
        // Straight down passes straight through.
        let t = transmitted(n, Vec3::NEG_Y, 1.0, 1.5).expect("passes");
        assert!((t - Vec3::NEG_Y).length() < 1e-6);
        // 45° into glass: sin θt = sin 45° / 1.5.
        let d = Vec3::new(1.0, -1.0, 0.0).normalize();
        let t = transmitted(n, d, 1.0, 1.5).expect("passes");
        let sin_t = t.x;
        assert!((sin_t - (0.5f32.sqrt() / 1.5)).abs() < 1e-6, "{t}");
        // Leaving glass at 45°: past the critical angle (41.8°), nothing is transmitted.
        assert_eq!(transmitted(n, d, 1.5, 1.0), None);
        // At index 1 nothing bends.
        let t = transmitted(n, d, 1.0, 1.0).expect("passes");
        assert!((t - d).length() < 1e-6);
    }
}
