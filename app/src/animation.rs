//! Animations for slides: one value of one Transform op swept over N frames, or the bounce
//! count of assignment 4 stepped from A to B (a frame each), each frame a full render (or the
//! compare view: (M⁻¹)ᵀ left, M right), written as a PNG sequence and an animated PNG. Used
//! by `tracelab animate` and the editor's File › Export animation.
//!
//! Memory does not grow with the frames: one copy of the scene has the op rewritten frame by
//! frame (a bounce sweep changes only the settings), each frame is rendered, written and
//! dropped, and the animated PNG is streamed to its temporary file frame by frame (put in
//! place only when complete).

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use tracelab_core::render::{
    MAX_BOUNCES, MAX_IMAGE_SIDE, Secondary, check_image_size, try_render_frame,
};
use tracelab_core::{
    CompiledScene, NodeId, NodeKind, NormalTransform, OutOfMemory, RenderSettings, Scene,
    TransformOp, View, check_scene,
};

use crate::io::output::check_output_folder;
use crate::io::{AtomicFile, OutputError, OutputPlan, write_implicit};

#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    pub node: NodeId,
    /// Index of the op in the Transform's list.
    pub op: usize,
    /// Which of the op's numbers (see [`components`]).
    pub component: usize,
    pub from: f32,
    pub to: f32,
    pub frames: u32,
}

impl Sweep {
    /// The value in frame `k`: from `from` to `to` inclusive, evenly. In f64, so that a
    /// sweep across most of f32's range (-3e38 to 3e38) has finite steps.
    pub fn value(&self, k: u32) -> f32 {
        if self.frames <= 1 || k == 0 {
            return self.from;
        }
        if k >= self.frames - 1 {
            return self.to;
        }
        let (from, to) = (f64::from(self.from), f64::from(self.to));
        (from + (to - from) * f64::from(k) / f64::from(self.frames - 1)) as f32
    }
}

/// The bounce count stepped from `from` to `to` inclusive, one frame each; the scene and
/// every other setting stay as they are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BounceSweep {
    pub from: u32,
    pub to: u32,
}

impl BounceSweep {
    /// Both ends at most [`MAX_BOUNCES`], `from` ≤ `to`; the message names the ends as
    /// `from_flag` and `to_flag`.
    pub fn check(&self, from_flag: &str, to_flag: &str) -> Result<(), String> {
        for (flag, v) in [(from_flag, self.from), (to_flag, self.to)] {
            if v > MAX_BOUNCES {
                return Err(format!("{flag} {v}: at most {MAX_BOUNCES} levels"));
            }
        }
        if self.from > self.to {
            return Err(format!(
                "{from_flag} {} is after {to_flag} {}: expected {from_flag} ≤ {to_flag}",
                self.from, self.to
            ));
        }
        Ok(())
    }

    /// One frame per bounce count (0 where the ends are the wrong way round).
    pub fn frames(&self) -> u32 {
        (self.to + 1).saturating_sub(self.from)
    }

    pub fn bounces(&self, k: u32) -> u32 {
        self.from.saturating_add(k)
    }
}

/// What changes from one frame to the next: one of two kinds of sweep, written alike.
#[derive(Clone, Debug, PartialEq)]
pub enum Animated {
    /// One number of one Transform op.
    Op(Sweep),
    /// The bounce count (`RenderSettings::secondary.bounces`).
    Bounces(BounceSweep),
}

impl Animated {
    pub fn frames(&self) -> u32 {
        match self {
            Animated::Op(s) => s.frames,
            Animated::Bounces(b) => b.frames(),
        }
    }
}

/// The names of an op's numbers, in the order `component` counts them.
pub fn components(op: &TransformOp) -> Vec<String> {
    match op {
        TransformOp::Scale(_) | TransformOp::Translate(_) => {
            ["x", "y", "z"].map(String::from).to_vec()
        }
        TransformOp::UniformScale(_) => vec!["factor".into()],
        TransformOp::XRotate(_) | TransformOp::YRotate(_) | TransformOp::ZRotate(_) => {
            vec!["degrees".into()]
        }
        TransformOp::Rotate { .. } => ["axis x", "axis y", "axis z", "degrees"]
            .map(String::from)
            .to_vec(),
        TransformOp::Matrix(_) => (0..16)
            .map(|i| format!("row {} col {}", i / 4, i % 4))
            .collect(),
    }
}

/// The op with one number replaced, or `None` for a component it does not have.
pub fn with_component(op: &TransformOp, c: usize, v: f32) -> Option<TransformOp> {
    let mut op = op.clone();
    match &mut op {
        TransformOp::Scale(x) | TransformOp::Translate(x) if c < 3 => x[c] = v,
        TransformOp::UniformScale(x)
        | TransformOp::XRotate(x)
        | TransformOp::YRotate(x)
        | TransformOp::ZRotate(x)
            if c == 0 =>
        {
            *x = v
        }
        TransformOp::Rotate { axis, .. } if c < 3 => axis[c] = v,
        TransformOp::Rotate { degrees, .. } if c == 3 => *degrees = v,
        // Written row by row; glam stores columns.
        TransformOp::Matrix(m) if c < 16 => m.col_mut(c % 4)[c / 4] = v,
        _ => return None,
    }
    Some(op)
}

/// The frames' scenes, one at a time: a single copy of the scene with the swept op rewritten
/// for each frame, so that frames share everything that does not change.
struct FrameScenes {
    scene: Scene,
    sweep: Sweep,
}

impl FrameScenes {
    /// Checks that the sweep names a number of an op of a Transform.
    fn new(scene: &Scene, sweep: &Sweep) -> Result<Self, String> {
        let mut frames = FrameScenes {
            scene: scene.clone(),
            sweep: sweep.clone(),
        };
        frames.op_mut()?;
        Ok(frames)
    }

    fn op_mut(&mut self) -> Result<&mut TransformOp, String> {
        let sweep = &self.sweep;
        let node = self
            .scene
            .graph
            .get_mut(sweep.node)
            .ok_or_else(|| format!("node #{} does not exist", sweep.node.0))?;
        let kind = node.kind.name();
        let NodeKind::Transform(ops) = &mut node.kind else {
            return Err(format!(
                "node #{} is a {kind}, not a Transform",
                sweep.node.0
            ));
        };
        let count = ops.len();
        let op = ops
            .get_mut(sweep.op)
            .ok_or_else(|| format!("the Transform has {count} ops: there is no op {}", sweep.op))?;
        if with_component(op, sweep.component, 0.0).is_none() {
            return Err(format!(
                "{} has {} numbers: there is no number {}",
                op.name(),
                components(op).len(),
                sweep.component
            ));
        }
        Ok(op)
    }

    /// The scene of frame `k`, checked against the same rules as every edit.
    fn frame(&mut self, k: u32) -> Result<&Scene, String> {
        let v = self.sweep.value(k);
        let component = self.sweep.component;
        let op = self.op_mut()?;
        if let Some(changed) = with_component(op, component, v) {
            *op = changed;
        }
        if let Some(p) = check_scene(&self.scene).into_iter().find(|p| !p.incomplete) {
            return Err(format!("frame {k} (value {v}): {}", p.message));
        }
        Ok(&self.scene)
    }
}

/// The scene of frame `k`, checked against the same rules as every edit.
pub fn frame_scene(scene: &Scene, sweep: &Sweep, k: u32) -> Result<Scene, String> {
    FrameScenes::new(scene, sweep)?.frame(k).cloned()
}

/// Each frame's scene and settings, for either kind of sweep.
enum FrameSource<'a> {
    // Boxed: a whole scene beside a reference and two numbers.
    Op(Box<FrameScenes>),
    Bounces(&'a Scene, BounceSweep),
}

impl<'a> FrameSource<'a> {
    /// Checks the whole sweep before any frame is rendered: every op value against the
    /// scene's rules, or every bounce count in bounds and the last one's rays under the cap.
    fn new(
        scene: &'a Scene,
        animated: &Animated,
        settings: &RenderSettings,
    ) -> Result<Self, AnimateError> {
        match animated {
            Animated::Op(sweep) => {
                let mut scenes = FrameScenes::new(scene, sweep).map_err(AnimateError::Refused)?;
                for k in 0..sweep.frames {
                    scenes.frame(k).map_err(AnimateError::Refused)?;
                }
                Ok(FrameSource::Op(Box::new(scenes)))
            }
            Animated::Bounces(b) => {
                b.check("the first bounce count", "the last")
                    .map_err(AnimateError::Refused)?;
                let compiled = CompiledScene::try_new(scene).map_err(|e| {
                    AnimateError::OutOfMemory(format!(
                        "not enough memory to prepare the scene (needs about {} MB more)",
                        tracelab_core::memory::megabytes(e.bytes)
                    ))
                })?;
                // The rays grow with the bounce count: the last frame is the worst.
                Secondary {
                    bounces: b.to,
                    ..settings.secondary
                }
                .check_bounded_as(&compiled, "bounces")
                .map_err(AnimateError::Refused)?;
                Ok(FrameSource::Bounces(scene, *b))
            }
        }
    }

    /// Frame `k`'s scene and settings.
    fn frame(
        &mut self,
        k: u32,
        settings: &RenderSettings,
    ) -> Result<(&Scene, RenderSettings), String> {
        match self {
            FrameSource::Op(scenes) => Ok((scenes.frame(k)?, *settings)),
            FrameSource::Bounces(scene, b) => {
                let mut s = *settings;
                s.secondary.bounces = b.bounces(k);
                Ok((*scene, s))
            }
        }
    }
}

/// One frame's picture as RGB bytes: the colour image, or the compare view side by side
/// (twice as wide). Every big buffer is allocated fallibly.
pub fn frame_image(
    scene: &Scene,
    settings: &RenderSettings,
    compare: bool,
) -> Result<Vec<u8>, OutOfMemory> {
    let compiled = CompiledScene::try_new(scene)?;
    let one = |rule: NormalTransform| {
        let settings = RenderSettings {
            normal_transform: rule,
            ..*settings
        };
        try_render_frame(&compiled, &settings)?.try_rgb8(View::Color, (0.0, 1.0))
    };
    if !compare {
        return one(settings.normal_transform);
    }
    let (a, b) = (
        one(NormalTransform::Correct)?,
        one(NormalTransform::Incorrect)?,
    );
    let row = settings.width as usize * 3;
    let mut out = tracelab_core::memory::try_with_capacity(a.len() * 2, "the compare view")?;
    for (ra, rb) in a.chunks_exact(row).zip(b.chunks_exact(row)) {
        out.extend_from_slice(ra);
        out.extend_from_slice(rb);
    }
    Ok(out)
}

/// The editor's export form: a sweep of either kind, the compare switch and the folder.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationForm {
    /// The Transform whose op is swept; `None` where none was selected: a bounce sweep only.
    pub node: Option<NodeId>,
    /// Sweep the bounce count instead of an op.
    pub bounce_sweep: bool,
    pub op: usize,
    pub component: usize,
    pub from: f32,
    pub to: f32,
    pub frames: u32,
    pub bounces: BounceSweep,
    pub compare: bool,
    pub folder: String,
}

impl AnimationForm {
    /// An op sweep of `node`'s Transform, or with no Transform a bounce sweep from 0 to
    /// `bounces` (the view's count, at least 1).
    pub fn new(node: Option<NodeId>, bounces: u32) -> Self {
        AnimationForm {
            node,
            bounce_sweep: node.is_none(),
            op: 0,
            component: 0,
            from: 0.0,
            to: 1.0,
            frames: 24,
            bounces: BounceSweep {
                from: 0,
                to: bounces.clamp(1, MAX_BOUNCES),
            },
            compare: false,
            folder: "animation".into(),
        }
    }

    /// What the form sweeps: the bounce count, or the op where a Transform is named.
    pub fn animated(&self) -> Animated {
        match self.node {
            Some(node) if !self.bounce_sweep => Animated::Op(Sweep {
                node,
                op: self.op,
                component: self.component,
                from: self.from,
                to: self.to,
                frames: self.frames,
            }),
            _ => Animated::Bounces(self.bounces),
        }
    }
}

#[derive(Debug, PartialEq)]
pub enum AnimateError {
    Cancelled {
        /// Frame files written before the cancel (kept; the animated PNG is not written).
        written: u32,
    },
    /// The scene or the sweep cannot make this animation (a frame's value is refused).
    Refused(String),
    /// The output cannot or may not be written (a name, a folder, a full disk); frames
    /// written before it are kept.
    Output(String),
    OutOfMemory(String),
}

/// Where an animation goes: `dir/stem_0000.png …` and `dir/stem.apng.png`, `delay_ms` a frame.
#[derive(Clone, Debug)]
pub struct Destination {
    pub dir: PathBuf,
    pub stem: String,
    pub delay_ms: u16,
    /// Files the command reads (the scene, its meshes): never written, whatever the names.
    pub inputs: Vec<PathBuf>,
}

/// Checks that a stem names files inside the folder: one plain name, no folder part (`..`,
/// `/`, an absolute path), nothing a file name cannot hold.
pub fn check_stem(stem: &str) -> Result<(), String> {
    let plain = !stem.is_empty()
        && stem != "."
        && stem != ".."
        && !stem.contains(['/', '\\', '\0'])
        && !stem.chars().any(char::is_control);
    if plain {
        Ok(())
    } else {
        Err(format!(
            "--stem {stem:?}: expected a plain file name (no folder, no \"..\", no control characters): \
             the frames are written inside --out"
        ))
    }
}

/// The picture size of every frame: the render size, twice as wide for the compare view,
/// checked against the image size limits.
pub fn frame_size(settings: &RenderSettings, compare: bool) -> Result<(u32, u32), String> {
    let w = if compare {
        settings.width.saturating_mul(2)
    } else {
        settings.width
    };
    check_image_size(w, settings.height).map_err(|e| {
        if compare {
            format!(
                "{e} (the compare view is twice the render's width: at most {} pixels wide \
                 per rule)",
                MAX_IMAGE_SIDE / 2
            )
        } else {
            e.to_string()
        }
    })?;
    Ok((w, settings.height))
}

/// Renders and writes every frame in order, each dropped once written, and the animated PNG
/// streamed beside them; `progress(done)` after each frame. Every frame's scene (or bounce
/// count) is checked before anything is rendered or written, so a sweep through a refused
/// value fails at once.
/// Returns the files written, the animated PNG last.
pub fn export(
    scene: &Scene,
    animated: &Animated,
    settings: &RenderSettings,
    compare: bool,
    to: &Destination,
    cancel: &AtomicBool,
    mut progress: impl FnMut(u32),
) -> Result<Vec<PathBuf>, AnimateError> {
    let frames = animated.frames();
    if frames == 0 {
        return Err(AnimateError::Refused(
            "an animation needs at least one frame".into(),
        ));
    }
    check_stem(&to.stem).map_err(AnimateError::Output)?;
    let (w, h) = frame_size(settings, compare).map_err(AnimateError::Output)?;
    let mut source = FrameSource::new(scene, animated, settings)?;
    let files = frame_files(to, frames)?;
    let write_err = |p: &Path, e: &dyn std::fmt::Display| {
        AnimateError::Output(format!("{}: cannot write: {e}", p.display()))
    };
    let apng_path = files.last().cloned().unwrap_or_default();
    let mut apng_file = BufWriter::new(
        AtomicFile::create_no_follow(&apng_path).map_err(|e| write_err(&apng_path, &e))?,
    );
    let mut apng = apng_writer(&mut apng_file, (w, h), frames, to.delay_ms)
        .map_err(|e| write_err(&apng_path, &e))?;
    for (k, path) in (0..frames).zip(&files) {
        if cancel.load(Ordering::Relaxed) {
            return Err(AnimateError::Cancelled { written: k });
        }
        let (scene, settings) = source.frame(k, settings).map_err(AnimateError::Refused)?;
        let rgb = frame_image(scene, &settings, compare).map_err(|e| {
            AnimateError::OutOfMemory(format!(
                "not enough memory to render frame {k} at {w}x{h} (needs about {} MB more)",
                tracelab_core::memory::megabytes(e.bytes)
            ))
        })?;
        let png = encode_png(&rgb, w, h).map_err(|e| write_err(path, &e))?;
        write_implicit(path, &png).map_err(|e| write_err(path, &e))?;
        apng.write_image_data(&rgb)
            .map_err(|e| write_err(&apng_path, &e))?;
        progress(k + 1);
    }
    apng.finish().map_err(|e| write_err(&apng_path, &e))?;
    apng_file
        .into_inner()
        .map_err(|e| e.into_error())
        .and_then(AtomicFile::commit)
        .map_err(|e| write_err(&apng_path, &e))?;
    Ok(files)
}

/// The files an export writes, in order, the animated PNG last, claimed through the output
/// policy (`io::output`): the folder made and checked, and no invented name that is a
/// symlink, a folder, a device or FIFO, or an input, refused before any frame is rendered.
fn frame_files(to: &Destination, frames: u32) -> Result<Vec<PathBuf>, AnimateError> {
    let refused = |e: OutputError| AnimateError::Output(e.to_string());
    std::fs::create_dir_all(&to.dir).map_err(|e| {
        AnimateError::Output(format!("{}: cannot create folder: {e}", to.dir.display()))
    })?;
    check_output_folder(&to.dir).map_err(refused)?;
    let mut plan = OutputPlan::new();
    for input in &to.inputs {
        plan.reads(input);
    }
    let files: Vec<PathBuf> = (0..frames)
        .map(|k| to.dir.join(format!("{}_{k:04}.png", to.stem)))
        .chain([to.dir.join(format!("{}.apng.png", to.stem))])
        .collect();
    for p in &files {
        plan.implicit_exact(p).map_err(refused)?;
    }
    Ok(files)
}

/// An animated PNG's writer (looping forever, `delay_ms` a frame) with its header written;
/// each `write_image_data` then streams one frame to `out`.
fn apng_writer<W: Write>(
    out: W,
    (w, h): (u32, u32),
    frames: u32,
    delay_ms: u16,
) -> Result<png::Writer<W>, png::EncodingError> {
    let mut enc = png::Encoder::new(out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_animated(frames.max(1), 0)?;
    enc.set_frame_delay(delay_ms, 1000)?;
    enc.write_header()
}

/// One frame as a PNG file's bytes, encoded as `render --output` encodes a PNG
/// (`io::encode_image`), so that a frame is the single render's file byte for byte.
fn encode_png(rgb: &[u8], w: u32, h: u32) -> image::ImageResult<Vec<u8>> {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes).write_image(
        rgb,
        w,
        h,
        image::ExtendedColorType::Rgb8,
    )?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn values_run_from_first_to_last_inclusive() {
        let s = Sweep {
            node: NodeId(0),
            op: 0,
            component: 0,
            from: 1.0,
            to: 3.0,
            frames: 5,
        };
        assert_eq!(
            (0..5).map(|k| s.value(k)).collect::<Vec<_>>(),
            [1.0, 1.5, 2.0, 2.5, 3.0]
        );
    }

    #[test]
    fn a_sweep_across_most_of_the_f32_range_has_finite_values() {
        let s = Sweep {
            node: NodeId(0),
            op: 0,
            component: 0,
            from: -3e38,
            to: 3e38,
            frames: 5,
        };
        let v: Vec<f32> = (0..5).map(|k| s.value(k)).collect();
        assert_eq!(v, [-3e38, -1.5e38, 0.0, 1.5e38, 3e38]);
    }

    #[test]
    fn a_bounce_sweep_has_a_frame_per_count_and_its_ends_are_checked() {
        let b = BounceSweep { from: 2, to: 5 };
        assert_eq!(b.frames(), 4);
        assert_eq!(
            (0..4).map(|k| b.bounces(k)).collect::<Vec<_>>(),
            [2, 3, 4, 5]
        );
        assert!(b.check("--a", "--b").is_ok());
        let late = BounceSweep { from: 3, to: 1 };
        assert_eq!(late.frames(), 0);
        assert!(late.check("--a", "--b").is_err_and(|m| m.contains("--a 3")));
        let deep = BounceSweep { from: 0, to: 101 };
        assert!(
            deep.check("--a", "--b")
                .is_err_and(|m| m.starts_with("--b 101"))
        );
        assert!(
            BounceSweep { from: 100, to: 100 }
                .check("--a", "--b")
                .is_ok()
        );
    }

    #[test]
    fn a_stem_is_one_plain_file_name() {
        assert!(check_stem("frame").is_ok());
        assert!(check_stem("my frames.v2").is_ok());
        for bad in [
            "", ".", "..", "../x", "a/b", "/tmp/x", "a\\b", "x\u{7}", "a\0b",
        ] {
            assert!(check_stem(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn a_component_is_one_number_of_the_op_as_written() {
        let m = with_component(&TransformOp::Matrix(glam::Mat4::IDENTITY), 1, 0.5)
            .expect("row 0 col 1");
        // Row 0, column 1: x' = x + 0.5 y.
        assert_eq!(
            m.matrix().transform_point3(Vec3::Y),
            Vec3::new(0.5, 1.0, 0.0)
        );
        assert_eq!(
            with_component(&TransformOp::Scale(Vec3::ONE), 2, 4.0),
            Some(TransformOp::Scale(Vec3::new(1.0, 1.0, 4.0)))
        );
        assert_eq!(with_component(&TransformOp::XRotate(0.0), 1, 4.0), None);
    }
}
