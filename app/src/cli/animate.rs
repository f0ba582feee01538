//! `tracelab animate`: one value of one Transform op swept over N frames, or the bounce
//! count stepped from A to B, to a PNG sequence and an animated PNG (see `crate::animation`).

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use tracelab_core::render::Secondary;
use tracelab_core::{CompiledScene, NodeId, RenderSettings};

use super::progress::Progress;
use super::render::{NormalMode, ObjectRaysMode};
use crate::animation::{
    AnimateError, Animated, BounceSweep, Destination, Sweep, check_stem, export, frame_size,
};
use crate::exit::{check_size, usage};
use crate::io::load_scene_and_meshes;

#[derive(clap::Args, Debug)]
pub struct AnimateArgs {
    pub scene: PathBuf,
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [200u32, 200])]
    pub size: Vec<u32>,
    /// An op sweep: the Transform's node id (as `tracelab inspect --json` names it:
    /// hit.path[].node.id).
    #[arg(long)]
    pub node: Option<u32>,
    /// Which op of the Transform, from 0 in file order (default 0).
    #[arg(long)]
    pub op: Option<usize>,
    /// Which number of the op, from 0 (x y z; degrees; a Matrix's 16 row by row; default 0).
    #[arg(long)]
    pub component: Option<usize>,
    #[arg(long, allow_negative_numbers = true)]
    pub from: Option<f32>,
    #[arg(long, allow_negative_numbers = true)]
    pub to: Option<f32>,
    /// Frames of an op sweep, 1 to 10000 (default 24).
    #[arg(long)]
    pub frames: Option<u32>,
    /// A bounce sweep instead: a frame per bounce count from A to B (0 to 100, A ≤ B).
    #[arg(long, value_name = "A", allow_negative_numbers = true)]
    pub bounces_from: Option<u32>,
    /// The bounce sweep's last count; the sweep's rays at B must stay under the render cap.
    #[arg(long, value_name = "B", allow_negative_numbers = true)]
    pub bounces_to: Option<u32>,
    /// Shadow rays toward every light (the course's -shadows).
    #[arg(long)]
    pub shadows: bool,
    /// Rays whose weight is below this are not traced (the course's -weight).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub weight: f32,
    /// Shade back-facing surfaces with the flipped normal instead of black.
    #[arg(long)]
    pub shade_back: bool,
    /// Milliseconds per frame in the animated PNG.
    #[arg(long, default_value_t = 100)]
    pub delay_ms: u16,
    /// Each frame as the compare view: (M⁻¹)ᵀ left, M right.
    #[arg(long)]
    pub compare: bool,
    #[arg(long, value_enum, default_value_t = NormalMode::Correct)]
    pub normal_transform: NormalMode,
    #[arg(long, value_enum, default_value_t = ObjectRaysMode::Unnormalized)]
    pub object_rays: ObjectRaysMode,
    /// Folder for FRAMES: STEM_0000.png … and STEM.apng.png.
    #[arg(long, default_value = ".")]
    pub out: PathBuf,
    /// The frame files' name, a plain file name: they are always written inside --out.
    #[arg(long, default_value = "frame")]
    pub stem: String,
}

/// The frames' bar.
const ANIMATE_PROGRESS: &str = "frames {pos}/{len} [{bar:30}] ({elapsed}, about {eta} left)";

/// The most frames an op sweep takes.
const MAX_FRAMES: u32 = 10_000;

/// Which sweep the flags ask for, checked: an op sweep (--node, --from, --to and their
/// companions) or a bounce sweep (--bounces-from, --bounces-to), never both.
fn animated(a: &AnimateArgs) -> anyhow::Result<Animated> {
    let op_flags: Vec<&str> = [
        ("--node", a.node.is_some()),
        ("--op", a.op.is_some()),
        ("--component", a.component.is_some()),
        ("--from", a.from.is_some()),
        ("--to", a.to.is_some()),
        ("--frames", a.frames.is_some()),
    ]
    .into_iter()
    .filter_map(|(f, given)| given.then_some(f))
    .collect();
    match (a.bounces_from, a.bounces_to) {
        (Some(from), Some(to)) => {
            if let Some(f) = op_flags.first() {
                return Err(usage(format!(
                    "{f} belongs to an op sweep: a bounce sweep (--bounces-from, --bounces-to) \
                     takes none of --node --op --component --from --to --frames"
                )));
            }
            let b = BounceSweep { from, to };
            b.check("--bounces-from", "--bounces-to").map_err(usage)?;
            Ok(Animated::Bounces(b))
        }
        (Some(_), None) => Err(usage("--bounces-from needs --bounces-to")),
        (None, Some(_)) => Err(usage("--bounces-to needs --bounces-from")),
        (None, None) => {
            let (Some(node), Some(from), Some(to)) = (a.node, a.from, a.to) else {
                return Err(usage(
                    "expected an op sweep (--node N --from X --to Y) or a bounce sweep \
                     (--bounces-from A --bounces-to B)",
                ));
            };
            let frames = a.frames.unwrap_or(24);
            if frames == 0 || frames > MAX_FRAMES {
                return Err(usage(format!(
                    "--frames {frames}: expected 1 to {MAX_FRAMES}"
                )));
            }
            if !from.is_finite() || !to.is_finite() {
                return Err(usage("--from and --to must be finite numbers"));
            }
            Ok(Animated::Op(Sweep {
                node: NodeId(node),
                op: a.op.unwrap_or(0),
                component: a.component.unwrap_or(0),
                from,
                to,
                frames,
            }))
        }
    }
}

pub fn run_animate(a: &AnimateArgs) -> anyhow::Result<()> {
    let &[w, h] = a.size.as_slice() else {
        return Err(usage("--size needs W H"));
    };
    check_size(w, h)?;
    let animated = animated(a)?;
    let secondary = Secondary {
        shadows: a.shadows,
        weight: a.weight,
        bounces: match &animated {
            Animated::Bounces(b) => b.to,
            Animated::Op(_) => 0,
        },
        ..Secondary::NONE
    };
    secondary
        .check_flags("--bounces-to", "--weight")
        .map_err(usage)?;
    check_stem(&a.stem).map_err(usage)?;
    let settings = RenderSettings {
        shade_back: a.shade_back,
        normal_transform: a.normal_transform.into(),
        object_rays: a.object_rays.into(),
        secondary: Secondary {
            bounces: 0,
            ..secondary
        },
        ..RenderSettings::new(w, h)
    };
    // The compare view is twice as wide: checked before the scene is read.
    frame_size(&settings, a.compare).map_err(usage)?;
    let (scene, meshes) = load_scene_and_meshes(Some(&a.scene))?;
    if let Animated::Bounces(_) = animated {
        // Rays that double at every bounce would never finish: the last frame, the worst,
        // refused as `render` refuses it, before any frame is written.
        let compiled = CompiledScene::try_new(&scene).map_err(|e| {
            anyhow::anyhow!("not enough memory to prepare the scene for rendering: {e}")
        })?;
        secondary
            .check_bounded_as(&compiled, "--bounces-to")
            .map_err(usage)?;
    }
    let to = Destination {
        dir: a.out.clone(),
        stem: a.stem.clone(),
        delay_ms: a.delay_ms,
        inputs: std::iter::once(a.scene.clone()).chain(meshes).collect(),
    };
    let never = AtomicBool::new(false);
    let mut bar = Progress::on_stderr(ANIMATE_PROGRESS, u64::from(animated.frames()));
    let result = export(
        &scene,
        &animated,
        &settings,
        a.compare,
        &to,
        &never,
        |done| {
            bar.set(u64::from(done));
        },
    );
    bar.finish();
    match result {
        Ok(files) => {
            if let Some(last) = files.last() {
                crate::io::write_stderr_text(&format!(
                    "wrote {} frames and {}\n",
                    files.len() - 1,
                    last.display()
                ));
            }
            Ok(())
        }
        Err(AnimateError::Refused(m)) => Err(anyhow::anyhow!("{}: {m}", a.scene.display())),
        Err(AnimateError::Output(m) | AnimateError::OutOfMemory(m)) => Err(anyhow::Error::msg(m)),
        Err(AnimateError::Cancelled { .. }) => Err(anyhow::anyhow!("cancelled")),
    }
}
