//! "What to do about the depth t": the lecture's three ways of moving a ray into object
//! space. tracelab's own rule keeps M⁻¹d as it is, so t_OS = t_WS; the other two normalise
//! it, once correctly (t rescaled back to world) and once as the classic bug (the
//! object-space t used as the world depth, so differently scaled objects overtake each other).

use super::compile::{CompiledScene, Hit, shape_hit, tie_bound};
use crate::geometry::Ray;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ObjectRays {
    /// Direction M⁻¹d not renormalised: the same t in both spaces (the lecture's choice 2).
    #[default]
    Unnormalized,
    /// Direction normalised; t_WS = t_OS / |M⁻¹d| after intersection (the lecture's choice 1).
    Normalized,
    /// Direction normalised and t_OS taken as the world t: wrong depths, and the wrong object
    /// in front between objects of different scales. CSG solids keep the correct rule (their
    /// operands' intervals are combined in world t).
    NormalizedNoRescale,
}

impl ObjectRays {
    pub const ALL: [ObjectRays; 3] = [
        ObjectRays::Unnormalized,
        ObjectRays::Normalized,
        ObjectRays::NormalizedNoRescale,
    ];

    /// The spelling of `--object-rays`.
    pub fn name(self) -> &'static str {
        match self {
            ObjectRays::Unnormalized => "unnormalized",
            ObjectRays::Normalized => "normalized",
            ObjectRays::NormalizedNoRescale => "normalized-no-rescale",
        }
    }

    pub fn from_name(s: &str) -> Option<ObjectRays> {
        Self::ALL.into_iter().find(|m| m.name() == s)
    }
}

/// How one object met a ray under a rule: the object-space ray as traced, and t in each space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectT {
    /// The ray as the intersection routine saw it (direction unit length unless unnormalised).
    pub traced: Ray,
    /// |M⁻¹d| for the world direction d (1 without a transform).
    pub direction_scale: f32,
    /// t along `traced`.
    pub t_object: f32,
    /// The world parameter of the point hit (o + t·d in world space).
    pub t_world: f32,
    /// What the renderer keeps as the hit's t (its depth and occlusion): `t_world`, except
    /// under `NormalizedNoRescale`, where it is `t_object`.
    pub t_used: f32,
}

impl CompiledScene {
    /// `intersect` under a rule. The default rule is the renderer's fast path; the others
    /// exist to be shown, so they trade speed for being plainly what the lecture describes.
    pub fn intersect_with(
        &self,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
        rule: ObjectRays,
    ) -> Option<Hit> {
        match rule {
            ObjectRays::Unnormalized => self.intersect(ray, t_min, t_max),
            ObjectRays::Normalized => {
                let mut best = None;
                let mut t_best = t_max;
                for &i in &self.unbounded {
                    if let Some((t, prim)) = self.intersect_object_with(
                        i,
                        ray,
                        t_min,
                        tie_bound(i, t_best, best.as_ref()),
                        rule,
                    ) {
                        t_best = t;
                        best = Some(Hit { t, object: i, prim });
                    }
                }
                // World t throughout, so the object boxes may prune as usual.
                self.bvh
                    .traverse(ray.origin, ray.direction, t_min, t_best, |i, t_max| {
                        let (t, prim) = self.intersect_object_with(
                            i,
                            ray,
                            t_min,
                            tie_bound(i, t_max, best.as_ref()),
                            rule,
                        )?;
                        best = Some(Hit { t, object: i, prim });
                        Some(t)
                    });
                best
            }
            ObjectRays::NormalizedNoRescale => {
                // Every object, keeping the smallest t as a homework's Group does: with t
                // meaning different things per object, box pruning in world t would add
                // errors of its own that are not the lecture's bug.
                let mut best: Option<Hit> = None;
                for i in 0..self.objects.len() as u32 {
                    let t_max = best.map_or(t_max, |b| b.t);
                    if let Some((t, prim)) = self.intersect_object_with(i, ray, t_min, t_max, rule)
                    {
                        best = Some(Hit { t, object: i, prim });
                    }
                }
                best
            }
        }
    }

    /// One object's closest hit under a rule: (the t the renderer keeps, prim). The range
    /// is in world t, except under the bug, which compares object-space t against it.
    pub fn intersect_object_with(
        &self,
        i: u32,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
        rule: ObjectRays,
    ) -> Option<(f32, u32)> {
        let o = self.objects.get(i as usize)?;
        let Some(xf) = &o.xf else {
            return shape_hit(&o.shape, ray, t_min, t_max);
        };
        let local = ray.transformed(&xf.object_from_world);
        match rule {
            ObjectRays::Unnormalized => shape_hit(&o.shape, &local, t_min, t_max),
            ObjectRays::Normalized => {
                let s = local.direction.length();
                let unit = Ray::new(local.origin, local.direction / s);
                let (t, prim) = shape_hit(&o.shape, &unit, t_min * s, t_max * s)?;
                Some((t / s, prim))
            }
            ObjectRays::NormalizedNoRescale => {
                let unit = Ray::new(local.origin, local.direction.normalize());
                shape_hit(&o.shape, &unit, t_min, t_max)
            }
        }
    }

    /// For a hit found under `rule`, the object-space ray and t in both spaces.
    pub fn object_t(&self, ray: &Ray, hit: &Hit, rule: ObjectRays) -> ObjectT {
        let xf = self
            .objects
            .get(hit.object as usize)
            .and_then(|o| o.xf.as_ref());
        let local = xf.map_or(*ray, |xf| ray.transformed(&xf.object_from_world));
        let s = if xf.is_some() {
            local.direction.length()
        } else {
            1.0
        };
        let unit = Ray::new(local.origin, local.direction / s);
        match (rule, xf) {
            (ObjectRays::Unnormalized, _) | (_, None) => ObjectT {
                traced: local,
                direction_scale: s,
                t_object: hit.t,
                t_world: hit.t,
                t_used: hit.t,
            },
            (ObjectRays::Normalized, Some(_)) => ObjectT {
                traced: unit,
                direction_scale: s,
                t_object: hit.t * s,
                t_world: hit.t,
                t_used: hit.t,
            },
            (ObjectRays::NormalizedNoRescale, Some(_)) => ObjectT {
                traced: unit,
                direction_scale: s,
                t_object: hit.t,
                t_world: hit.t / s,
                t_used: hit.t,
            },
        }
    }

    /// A world ray on which `hit.t` lands on the point really hit, for the normal routines
    /// (which evaluate the ray at `hit.t`): the ray itself, except under the bug, where
    /// `hit.t` is an object-space distance, so the direction is shortened by |M⁻¹d|.
    #[inline]
    pub fn ray_for_hit_point(&self, ray: &Ray, hit: &Hit, rule: ObjectRays) -> Ray {
        if rule != ObjectRays::NormalizedNoRescale {
            return *ray;
        }
        match self
            .objects
            .get(hit.object as usize)
            .and_then(|o| o.xf.as_ref())
        {
            Some(xf) => {
                let s = xf
                    .object_from_world
                    .transform_vector3(ray.direction)
                    .length();
                Ray::new(ray.origin, ray.direction / s)
            }
            None => *ray,
        }
    }
}
