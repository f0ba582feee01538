//! `tracelab animate`: one value of one Transform op swept over N frames, to a PNG sequence
//! and an animated PNG (see `crate::animation`).

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use tracelab_core::{NodeId, RenderSettings};

use super::progress::Progress;
use super::render::{NormalMode, ObjectRaysMode};
use crate::animation::{AnimateError, Destination, Sweep, check_stem, export, frame_size};
use crate::exit::{check_size, usage};
use crate::io::load_scene_and_meshes;

#[derive(clap::Args, Debug)]
pub struct AnimateArgs {
    pub scene: PathBuf,
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [200u32, 200])]
    pub size: Vec<u32>,
    /// The Transform's node id (as `tracelab inspect --json` names it: hit.path[].node.id).
    #[arg(long)]
    pub node: u32,
    /// Which op of the Transform, from 0 in file order.
    #[arg(long, default_value_t = 0)]
    pub op: usize,
    /// Which number of the op, from 0 (x y z; degrees; a Matrix's 16 row by row).
    #[arg(long, default_value_t = 0)]
    pub component: usize,
    #[arg(long, allow_negative_numbers = true)]
    pub from: f32,
    #[arg(long, allow_negative_numbers = true)]
    pub to: f32,
    #[arg(long, default_value_t = 24)]
    pub frames: u32,
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

pub fn run_animate(a: &AnimateArgs) -> anyhow::Result<()> {
    let &[w, h] = a.size.as_slice() else {
        return Err(usage("--size needs W H"));
    };
    check_size(w, h)?;
    if a.frames == 0 || a.frames > 10_000 {
        return Err(usage(format!("--frames {}: expected 1 to 10000", a.frames)));
    }
    if !a.from.is_finite() || !a.to.is_finite() {
        return Err(usage("--from and --to must be finite numbers"));
    }
    check_stem(&a.stem).map_err(usage)?;
    let settings = RenderSettings {
        normal_transform: a.normal_transform.into(),
        object_rays: a.object_rays.into(),
        ..RenderSettings::new(w, h)
    };
    // The compare view is twice as wide: checked before the scene is read.
    frame_size(&settings, a.compare).map_err(usage)?;
    let (scene, meshes) = load_scene_and_meshes(Some(&a.scene))?;
    let sweep = Sweep {
        node: NodeId(a.node),
        op: a.op,
        component: a.component,
        from: a.from,
        to: a.to,
        frames: a.frames,
    };
    let to = Destination {
        dir: a.out.clone(),
        stem: a.stem.clone(),
        delay_ms: a.delay_ms,
        inputs: std::iter::once(a.scene.clone()).chain(meshes).collect(),
    };
    let never = AtomicBool::new(false);
    let mut bar = Progress::on_stderr(ANIMATE_PROGRESS, u64::from(a.frames));
    let result = export(&scene, &sweep, &settings, a.compare, &to, &never, |done| {
        bar.set(u64::from(done));
    });
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
