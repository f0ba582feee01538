//! Animations for slides: one value of one Transform op swept over N frames, each frame a
//! full render (or the compare view: (M⁻¹)ᵀ left, M right), written as a PNG sequence and an
//! animated PNG. Used by `tracelab animate` and the editor's File › Export animation.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use image::RgbImage;
use tracelab_core::{
    CompiledScene, NodeId, NodeKind, NormalTransform, RenderSettings, Scene, TransformOp, View,
    check_scene, render_frame,
};

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
    /// The value in frame `k`: from `from` to `to` inclusive, evenly.
    pub fn value(&self, k: u32) -> f32 {
        if self.frames <= 1 {
            return self.from;
        }
        self.from + (self.to - self.from) * k as f32 / (self.frames - 1) as f32
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

/// The scene of frame `k`, checked against the same rules as every edit.
pub fn frame_scene(scene: &Scene, sweep: &Sweep, k: u32) -> Result<Scene, String> {
    let mut s = scene.clone();
    let v = sweep.value(k);
    let node = s
        .graph
        .get_mut(sweep.node)
        .ok_or_else(|| format!("node #{} does not exist", sweep.node.0))?;
    let NodeKind::Transform(ops) = &mut node.kind else {
        return Err(format!(
            "node #{} is a {}, not a Transform",
            sweep.node.0,
            node.kind.name()
        ));
    };
    let count = ops.len();
    let op = ops
        .get_mut(sweep.op)
        .ok_or_else(|| format!("the Transform has {count} ops: there is no op {}", sweep.op))?;
    *op = with_component(op, sweep.component, v).ok_or_else(|| {
        format!(
            "{} has {} numbers: there is no number {}",
            op.name(),
            components(op).len(),
            sweep.component
        )
    })?;
    if let Some(p) = check_scene(&s).into_iter().find(|p| !p.incomplete) {
        return Err(format!("frame {k} (value {v}): {}", p.message));
    }
    Ok(s)
}

/// One frame's picture: the colour image, or the compare view side by side.
pub fn frame_image(scene: &Scene, settings: &RenderSettings, compare: bool) -> RgbImage {
    let compiled = CompiledScene::new(scene);
    let one = |rule: NormalTransform| {
        let f = render_frame(
            &compiled,
            &RenderSettings {
                normal_transform: rule,
                ..*settings
            },
        );
        RgbImage::from_raw(f.width, f.height, f.rgb8(View::Color, (0.0, 1.0))).expect("frame size")
    };
    if !compare {
        return one(settings.normal_transform);
    }
    let (a, b) = (
        one(NormalTransform::Correct),
        one(NormalTransform::Incorrect),
    );
    let mut out = RgbImage::new(a.width() * 2, a.height());
    image::imageops::replace(&mut out, &a, 0, 0);
    image::imageops::replace(&mut out, &b, i64::from(a.width()), 0);
    out
}

/// The editor's export form: a sweep, the compare switch and the folder.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationForm {
    pub node: NodeId,
    pub op: usize,
    pub component: usize,
    pub from: f32,
    pub to: f32,
    pub frames: u32,
    pub compare: bool,
    pub folder: String,
}

impl AnimationForm {
    pub fn new(node: NodeId) -> Self {
        AnimationForm {
            node,
            op: 0,
            component: 0,
            from: 0.0,
            to: 1.0,
            frames: 24,
            compare: false,
            folder: "animation".into(),
        }
    }

    pub fn sweep(&self) -> Sweep {
        Sweep {
            node: self.node,
            op: self.op,
            component: self.component,
            from: self.from,
            to: self.to,
            frames: self.frames,
        }
    }
}

#[derive(Debug, PartialEq)]
pub enum AnimateError {
    Cancelled,
    Refused(String),
}

/// Every frame, in order; `progress(done)` after each. Every frame's scene is checked
/// before any is rendered, so a sweep through a refused value fails at once.
pub fn render_frames(
    scene: &Scene,
    sweep: &Sweep,
    settings: &RenderSettings,
    compare: bool,
    cancel: &AtomicBool,
    mut progress: impl FnMut(u32),
) -> Result<Vec<RgbImage>, AnimateError> {
    if sweep.frames == 0 {
        return Err(AnimateError::Refused(
            "an animation needs at least one frame".into(),
        ));
    }
    let scenes = (0..sweep.frames)
        .map(|k| frame_scene(scene, sweep, k))
        .collect::<Result<Vec<_>, _>>()
        .map_err(AnimateError::Refused)?;
    let mut out = Vec::with_capacity(scenes.len());
    for (k, s) in scenes.iter().enumerate() {
        if cancel.load(Ordering::Relaxed) {
            return Err(AnimateError::Cancelled);
        }
        out.push(frame_image(s, settings, compare));
        progress(k as u32 + 1);
    }
    Ok(out)
}

/// Writes `dir/stem_0000.png …` and the animated `dir/stem.apng.png`; returns the files.
pub fn write_frames(
    frames: &[RgbImage],
    dir: &Path,
    stem: &str,
    delay_ms: u16,
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir)
        .map_err(|e| format!("{}: cannot create folder: {e}", dir.display()))?;
    let mut written = Vec::new();
    for (k, f) in frames.iter().enumerate() {
        let p = dir.join(format!("{stem}_{k:04}.png"));
        let mut bytes = Vec::new();
        f.write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| format!("{}: cannot encode: {e}", p.display()))?;
        crate::io::write_atomic(&p, &bytes)
            .map_err(|e| format!("{}: cannot write: {e}", p.display()))?;
        written.push(p);
    }
    let p = dir.join(format!("{stem}.apng.png"));
    let bytes =
        apng(frames, delay_ms).map_err(|e| format!("{}: cannot encode: {e}", p.display()))?;
    crate::io::write_atomic(&p, &bytes)
        .map_err(|e| format!("{}: cannot write: {e}", p.display()))?;
    written.push(p);
    Ok(written)
}

/// An animated PNG (looping forever), `delay_ms` per frame.
pub fn apng(frames: &[RgbImage], delay_ms: u16) -> Result<Vec<u8>, png::EncodingError> {
    let (w, h) = frames.first().map_or((1, 1), |f| f.dimensions());
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_animated(frames.len().max(1) as u32, 0)?;
        enc.set_frame_delay(delay_ms, 1000)?;
        let mut writer = enc.write_header()?;
        for f in frames {
            writer.write_image_data(f.as_raw())?;
        }
        writer.finish()?;
    }
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
