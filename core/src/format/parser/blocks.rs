//! The top level and its flat blocks: camera, Lights, Background, Materials.

use glam::Vec3;

use super::super::lexer::TokKind;
use super::Parser;
use super::fields::block_comments;
use super::objects::OBJECT_KEYWORDS;
use crate::scene::phong_field;
use crate::scene::{
    Anchor, Background, Camera, Comments, Light, LightKind, Material, MaterialKeyword, TextureKind,
    validate,
};

impl Parser<'_> {
    pub(super) fn parse_file(&mut self) {
        while let Some(t) = self.next() {
            match t.kind {
                TokKind::Open => {
                    self.error(t.start, "unexpected \"{\" outside any block");
                    self.skip_block();
                }
                TokKind::Close => self.error(t.start, "unexpected \"}\" outside any block"),
                TokKind::Word => {
                    let kw = self.text(t);
                    match kw {
                        "OrthographicCamera" | "PerspectiveCamera" => {
                            self.camera_seen = true;
                            self.parse_camera(kw, t.start)
                        }
                        "Lights" => self.parse_lights(t.start),
                        "Background" => self.parse_background(t.start),
                        "Materials" => self.parse_materials(t.start),
                        "Group" => {
                            self.group_seen = true;
                            self.parse_object_tree(t.start)
                        }
                        _ => {
                            let hint = if OBJECT_KEYWORDS.contains(&kw) {
                                " (objects belong inside the top-level Group)"
                            } else {
                                " (expected OrthographicCamera, PerspectiveCamera, Lights, Background, Materials or Group)"
                            };
                            self.error(t.start, format!("unknown keyword \"{kw}\"{hint}"));
                            if self.peek().is_some_and(|n| n.kind == TokKind::Open) {
                                self.pos += 1;
                                self.skip_block();
                            }
                        }
                    }
                }
            }
        }
    }

    fn parse_camera(&mut self, kw: &str, off: usize) {
        let before = self.comments_here();
        let Some(open) = self.expect_open(kw) else {
            return;
        };
        let Some((mut f, end)) = self.read_fields(kw, open) else {
            return;
        };
        self.scene_comments.camera = block_comments(before, &mut f, end);
        if self.camera.is_some() {
            self.error(off, "a scene has one camera; this is a second");
        }
        let center = self.take_vec3(&mut f, kw, off, "center");
        let direction = self.take_vec3(&mut f, kw, off, "direction");
        let up = self.take_vec3(&mut f, kw, off, "up");
        let perspective = kw == "PerspectiveCamera";
        let last = if perspective { "angle" } else { "size" };
        let extent = self.take_f32(&mut f, kw, off, last);
        self.reject_unused(&f, kw, &format!("center, direction, up, {last}"));
        let (Some(center), Some(direction), Some(up), Some(extent)) =
            (center, direction, up, extent)
        else {
            return;
        };
        let camera = if perspective {
            Camera::Perspective {
                center,
                direction,
                up,
                angle: extent,
            }
        } else {
            Camera::Orthographic {
                center,
                direction,
                up,
                size: extent,
            }
        };
        if let Err(e) = validate::check_camera(&camera) {
            self.error(off, e.message);
            return;
        }
        self.camera = Some(camera);
    }

    fn parse_background(&mut self, off: usize) {
        let before = self.comments_here();
        let Some(open) = self.expect_open("Background") else {
            return;
        };
        let Some((mut f, end)) = self.read_fields("Background", open) else {
            return;
        };
        self.scene_comments.background = block_comments(before, &mut f, end);
        let mut bg = Background::default();
        if f.iter().any(|x| x.name == "color") {
            bg.color = self.take_vec3(&mut f, "Background", off, "color");
        }
        if f.iter().any(|x| x.name == "ambientLight") {
            bg.ambient = self.take_vec3(&mut f, "Background", off, "ambientLight");
        }
        self.reject_unused(&f, "Background", "color, ambientLight");
        if self.background.is_some() {
            self.error(off, "a scene has one Background; this is a second");
        }
        self.background = Some(bg);
    }

    fn parse_lights(&mut self, off: usize) {
        let mut lights = Vec::new();
        let list = ListBlock {
            block: "Lights",
            count: "numLights",
            noun: "light",
            expected: "numLights, DirectionalLight or PointLight",
        };
        let second = self.lights.is_some();
        let read = self.read_list_block(&list, off, second, |this, kw, at| match kw {
            "DirectionalLight" | "PointLight" => {
                if let Some(light) = this.parse_light(kw, at) {
                    lights.push(light);
                }
                true
            }
            _ => false,
        });
        let Some((comments, declared)) = read else {
            return;
        };
        self.check_list_count(&list, off, declared, lights.len());
        self.scene_comments.lights = comments;
        self.lights = Some(lights);
    }

    /// `DirectionalLight { direction color }` or `PointLight { position color
    /// [attenuation] }` (assignment 4; attenuation defaults to the course's 1 0 0).
    fn parse_light(&mut self, kw: &str, off: usize) -> Option<Light> {
        let before = self.comments_here();
        let open = self.expect_open(kw)?;
        let (mut f, end) = self.read_fields(kw, open)?;
        let comments = block_comments(before, &mut f, end);
        let kind = if kw == "PointLight" {
            let p = self.take_vec3(&mut f, kw, off, "position");
            let c = self.take_vec3(&mut f, kw, off, "color");
            let mut attenuation = None;
            if f.iter().any(|x| x.name == "attenuation") {
                attenuation = Some(self.take_vec3(&mut f, kw, off, "attenuation"));
            }
            self.reject_unused(&f, kw, "position, color, attenuation");
            let attenuation = match attenuation {
                Some(a) => Some(a?),
                None => None,
            };
            (
                LightKind::Point {
                    position: p?,
                    attenuation,
                },
                c?,
            )
        } else {
            let d = self.take_vec3(&mut f, kw, off, "direction");
            let c = self.take_vec3(&mut f, kw, off, "color");
            self.reject_unused(&f, kw, "direction, color");
            (LightKind::Directional { direction: d? }, c?)
        };
        let light = Light {
            kind: kind.0,
            color: kind.1,
            comments,
        };
        if let Err(e) = validate::check_light(&light) {
            self.error(
                self.field_offset(&f, &e.field.name()).unwrap_or(off),
                e.message,
            );
        }
        Some(light)
    }

    pub(super) fn parse_material_block(&mut self, kw: &str, off: usize) -> Option<Material> {
        let before = self.comments_here();
        let open = self.expect_open(kw)?;
        let (mut f, end) = self.read_fields(kw, open)?;
        let diffuse = self.take_vec3(&mut f, kw, off, "diffuseColor")?;
        let mut ok = true;
        for (i, x) in f.iter().enumerate() {
            let msg = if x.word.is_some() {
                format!(
                    "\"{}\" belongs in TriangleMesh, not in {kw} (material fields take numbers)",
                    x.name
                )
            } else if f[..i].iter().any(|y| y.name == x.name) {
                format!("\"{}\" is given twice in {kw}", x.name)
            } else {
                continue;
            };
            self.error(x.name_off, msg);
            ok = false;
        }
        // Each field's count of numbers, once the block's shape is sound.
        let sound = ok;
        for x in f.iter().filter(|_| sound) {
            match phong_field(&x.name) {
                Some(p) if x.values.len() != p.numbers => {
                    let msg = format!(
                        "\"{}\" takes {} number(s), found {}",
                        x.name,
                        p.numbers,
                        x.values.len()
                    );
                    self.error(x.name_off, msg);
                    ok = false;
                }
                Some(_) => {}
                None if x.name == "diffuseColor" => {}
                None if x.values.is_empty() => {
                    let msg = format!(
                        "\"{}\" has no numbers: a material field is a name and its numbers \
                         (expected diffuseColor, specularColor, exponent, reflectiveColor, \
                         transparentColor or indexOfRefraction)",
                        x.name
                    );
                    self.error(x.name_off, msg);
                    ok = false;
                }
                None => self.warn(
                    x.name_off,
                    format!(
                        "\"{}\" is not a field tracelab renders (a material has diffuseColor, \
                         specularColor, exponent, reflectiveColor, transparentColor, \
                         indexOfRefraction); kept and written back, not used",
                        x.name
                    ),
                ),
            }
        }
        if !ok {
            return None;
        }
        let keyword = if kw == "PhongMaterial" {
            MaterialKeyword::PhongMaterial
        } else {
            MaterialKeyword::Material
        };
        // The Phong fields and any others, in the file's order (`Material::phong` reads them).
        let extra = f
            .iter()
            .filter(|x| !x.used)
            .map(|x| (x.name.clone(), x.values.iter().map(|v| v.0).collect()))
            .collect();
        let comments = block_comments(before, &mut f, end);
        let m = Material {
            diffuse,
            keyword,
            extra,
            texture: None,
            comments,
        };
        // Ranges (a negative exponent, an index of refraction ≤ 0), at the field at fault.
        if let Err(e) = validate::check_material(&m) {
            self.error(
                self.field_offset(&f, &e.field.name()).unwrap_or(off),
                e.message,
            );
            return None;
        }
        Some(m)
    }

    fn parse_materials(&mut self, off: usize) {
        let list = ListBlock {
            block: "Materials",
            count: "numMaterials",
            noun: "material",
            expected: "numMaterials, Material, PhongMaterial, Checkerboard, Noise, Marble or Wood",
        };
        let mut count = 0;
        let read = self.read_list_block(&list, off, false, |this, kw, at| match kw {
            "Material" | "PhongMaterial" => {
                count += 1;
                if let Some(m) = this.parse_material_block(kw, at) {
                    this.materials.push(m);
                }
                true
            }
            _ => match TextureKind::from_name(kw) {
                Some(kind) => {
                    count += 1;
                    // A broken one still takes its index (the file is refused anyway), so
                    // the MaterialIndex lines after it are not reported out of range too.
                    let m = this.parse_texture_block(kind, at);
                    this.materials
                        .push(m.unwrap_or_else(|| Material::diffuse(Vec3::ZERO)));
                    true
                }
                None => false,
            },
        });
        let Some((comments, declared)) = read else {
            return;
        };
        self.check_list_count(&list, off, declared, count);
        self.scene_comments.materials = comments;
    }

    /// Reads a list block (`Lights`, `Materials`) after its keyword up to its `}`: its count
    /// and, through `item` (false for a keyword it does not know), its items. `second`: the
    /// scene already has one. None (reported) when the block is not closed.
    fn read_list_block(
        &mut self,
        list: &ListBlock,
        off: usize,
        second: bool,
        mut item: impl FnMut(&mut Self, &str, usize) -> bool,
    ) -> Option<(Comments, Option<(usize, usize)>)> {
        let mut comments = Comments {
            before: self.comments_here(),
            ..Comments::default()
        };
        let open = self.expect_open(list.block)?;
        if second {
            let msg = format!("a scene has one {} block; this is a second", list.block);
            self.error(off, msg);
        }
        let mut declared = None;
        loop {
            let Some(t) = self.next() else {
                self.error(
                    open,
                    format!(
                        "unterminated {} block: expected \"}}\" before the end of the file",
                        list.block
                    ),
                );
                return None;
            };
            let w = self.text(t);
            match t.kind {
                TokKind::Close => {
                    comments.end = self.comments_here();
                    break;
                }
                TokKind::Word if w == list.count => {
                    let c = self.comments_here();
                    if !c.is_empty() {
                        comments
                            .inner
                            .entry(Anchor::Field(list.count.into()))
                            .or_default()
                            .extend(c);
                    }
                    declared = self.expect_count(list.count);
                }
                _ => {
                    if t.kind == TokKind::Word && item(self, w, t.start) {
                        continue;
                    }
                    self.error(
                        t.start,
                        format!(
                            "unknown keyword \"{w}\" in {} (expected {})",
                            list.block, list.expected
                        ),
                    );
                    if t.kind == TokKind::Open
                        || self.peek().is_some_and(|n| n.kind == TokKind::Open)
                    {
                        if t.kind != TokKind::Open {
                            self.pos += 1;
                        }
                        self.skip_block();
                    }
                }
            }
        }
        Some((comments, declared))
    }

    /// The count a list block declares against the items it holds.
    fn check_list_count(
        &mut self,
        list: &ListBlock,
        off: usize,
        declared: Option<(usize, usize)>,
        held: usize,
    ) {
        let ListBlock {
            block, count, noun, ..
        } = list;
        match declared {
            Some((n, at)) if n != held => self.error(
                at,
                format!("{count} says {n} but the block holds {held} {noun}(s)"),
            ),
            None => self.warn(
                off,
                format!("{block} has no {count}; counting the {noun}s instead"),
            ),
            _ => {}
        }
    }
}

/// The words of a list block's messages.
struct ListBlock {
    block: &'static str,
    count: &'static str,
    noun: &'static str,
    expected: &'static str,
}
