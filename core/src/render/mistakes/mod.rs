//! The catalogue of known student mistakes, each a render variant: what a ray tracer that
//! breaks one of the course's rules draws, so `tracelab diff` can name the rule a student's
//! image breaks. A variant is one or two mistakes at once; with none (`RenderSettings::variant`
//! = `None`) nothing here runs and the render is today's, bit for bit.
//!
//! - `catalogue.rs`: each mistake's name, explanation, rule and where it can show;
//! - `transforms.rs`: the course parser's transform rules (a variant's own scene);
//! - `variant_render.rs`: the one-ray-per-pixel render of a variant and its image bytes.

mod catalogue;
mod transforms;
mod variant_render;

pub use catalogue::{Mistake, Variant, Views, scene_with};
pub use variant_render::{render_variant, variant_rgb8};
