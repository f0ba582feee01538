//! Solid textures (assignment 6): a material that picks or blends two other materials by a
//! function of the hit point moved into texture space by its own Transform.

use glam::DMat4;

use super::{TransformOp, compose_f64};

/// Which function of the texture-space point a texture is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureKind {
    /// Unit cells by floor parity: material A on even cells, B on odd ones.
    Checkerboard,
    /// Perlin's turbulence N(x) blends A into B.
    Noise,
    /// sin(frequency·x + amplitude·N(x)) blends A into B.
    Marble,
    /// Rings about the y axis, bent by N(x), blend A into B.
    Wood,
}

impl TextureKind {
    pub const ALL: [TextureKind; 4] = [
        TextureKind::Checkerboard,
        TextureKind::Noise,
        TextureKind::Marble,
        TextureKind::Wood,
    ];

    /// The keyword in a Materials block.
    pub fn name(self) -> &'static str {
        match self {
            TextureKind::Checkerboard => "Checkerboard",
            TextureKind::Noise => "Noise",
            TextureKind::Marble => "Marble",
            TextureKind::Wood => "Wood",
        }
    }

    pub fn from_name(word: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == word)
    }

    /// Whether the block has an `octaves` line (all but Checkerboard).
    pub fn has_octaves(self) -> bool {
        self != TextureKind::Checkerboard
    }

    /// Whether the block has `frequency` and `amplitude` lines (Marble and Wood).
    pub fn has_waves(self) -> bool {
        matches!(self, TextureKind::Marble | TextureKind::Wood)
    }
}

/// The most octaves a texture may sum: past about 24 a term is below an f32 ulp of the
/// first, so more only cost time.
pub const MAX_OCTAVES: u32 = 32;

/// A texture material's own data; its colours come from the two materials it names.
#[derive(Clone, Debug, PartialEq)]
pub struct SolidTexture {
    pub kind: TextureKind,
    /// The ops of its `Transform` block, composed as an object's are, mapping world points
    /// to texture space; `None` when the block has no Transform (the identity).
    pub transform: Option<Vec<TransformOp>>,
    /// The two `materialIndex` lines, in the file's order: A then B.
    pub materials: [u32; 2],
    /// Noise, Marble, Wood: how many octaves N sums (0 for a Checkerboard).
    pub octaves: u32,
    /// Marble, Wood (0 for the others).
    pub frequency: f32,
    /// Marble, Wood (0 for the others).
    pub amplitude: f32,
}

impl SolidTexture {
    /// A texture of `kind` between materials `a` and `b` with the identity transform and
    /// the numbers the course's scenes use most (octaves 5, frequency 3, amplitude 2).
    pub fn new(kind: TextureKind, a: u32, b: u32) -> Self {
        SolidTexture {
            kind,
            transform: None,
            materials: [a, b],
            octaves: if kind.has_octaves() { 5 } else { 0 },
            frequency: if kind.has_waves() { 3.0 } else { 0.0 },
            amplitude: if kind.has_waves() { 2.0 } else { 0.0 },
        }
    }

    /// The texture-from-world matrix: a world point p goes to M·p (column vector), M the
    /// ops composed left to right as for an object's Transform.
    pub fn texture_from_world(&self) -> DMat4 {
        self.transform
            .as_deref()
            .map_or(DMat4::IDENTITY, compose_f64)
    }
}
