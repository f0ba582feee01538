//! A parallel reader for the plain OBJ files scanned meshes come as (`v x y z` and
//! `f a b c ...` with positive indices, optionally `a/t/n`). Anything else it does not
//! understand makes it give up, and the caller reads the file with tobj, which stays the
//! reference. It exists for speed: tobj spends ~1 s on the 871k-triangle dragon.
//!
//! It accepts only files tobj also reads, with the same triangles: whatever tobj would reject
//! (a bad `vn`, a texture index past the `vt`s read so far, `usemtl` without a name, text
//! that is not UTF-8) makes it give up too, so tobj reports it.

use glam::Vec3;
use rayon::prelude::*;

/// Below this size one thread reads the whole file.
const CHUNK: usize = 1 << 19;

#[derive(Default)]
struct Chunk {
    verts: Vec<Vec3>,
    /// 1-based vertex indices as written.
    faces: Vec<[u32; 3]>,
    /// `vt` and `vn` lines in the chunk.
    texcoords: i64,
    normals: i64,
    /// Largest (index − entries read so far in this chunk) over the chunk's faces, for
    /// positions, texture coordinates and normals: the chunk is valid when the entries of
    /// all earlier chunks cover it.
    excess: [i64; 3],
}

/// Positions and triangles (fan-triangulated, as tobj does), or None when the file needs tobj.
pub fn parse(bytes: &[u8]) -> Option<(Vec<Vec3>, Vec<[u32; 3]>)> {
    // tobj reads lines of UTF-8 and fails on anything else.
    std::str::from_utf8(bytes).ok()?;
    let chunks = split_lines(bytes, CHUNK);
    let parsed: Vec<Chunk> = chunks
        .par_iter()
        .map(|&(a, b)| parse_chunk(&bytes[a..b]))
        .collect::<Option<_>>()?;
    let mut base = [0i64; 3];
    for c in &parsed {
        if (0..3).any(|k| c.excess[k] > base[k]) {
            return None;
        }
        base[0] += c.verts.len() as i64;
        base[1] += c.texcoords;
        base[2] += c.normals;
    }
    let nv: usize = parsed.iter().map(|c| c.verts.len()).sum();
    let nf: usize = parsed.iter().map(|c| c.faces.len()).sum();
    let mut positions = Vec::with_capacity(nv);
    let mut triangles = Vec::with_capacity(nf);
    for c in parsed {
        positions.extend_from_slice(&c.verts);
        triangles.extend(c.faces.iter().map(|f| f.map(|i| i - 1)));
    }
    Some((positions, triangles))
}

/// Byte ranges of roughly `size` bytes, each ending after a newline (or at the end).
fn split_lines(bytes: &[u8], size: usize) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    while start < bytes.len() {
        let mut end = (start + size).min(bytes.len());
        while end < bytes.len() && bytes[end - 1] != b'\n' {
            end += 1;
        }
        out.push((start, end));
        start = end;
    }
    out
}

fn parse_chunk(text: &[u8]) -> Option<Chunk> {
    let mut c = Chunk {
        excess: [i64::MIN; 3],
        ..Chunk::default()
    };
    let mut poly: Vec<u32> = Vec::new();
    for line in text.split(|&b| b == b'\n') {
        let mut words = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty());
        let Some(key) = words.next() else { continue };
        match key {
            b"v" => {
                let mut xyz = [0.0f32; 3];
                for x in &mut xyz {
                    *x = std::str::from_utf8(words.next()?).ok()?.parse().ok()?;
                }
                if words.next().is_some() {
                    return None; // w or vertex colours: tobj's business
                }
                c.verts.push(Vec3::from(xyz));
            }
            b"f" => {
                poly.clear();
                let mut most = [0u32; 3];
                for w in words {
                    let mut parts = w.split(|&b| b == b'/');
                    let v = parse_index(parts.next()?)?;
                    most[0] = most[0].max(v);
                    // `v/t`, `v//n`, `v/t/n`: the others must be in range too, or tobj fails.
                    for (k, part) in parts.enumerate() {
                        if k >= 2 {
                            return None;
                        }
                        if !(k == 0 && part.is_empty()) {
                            most[k + 1] = most[k + 1].max(parse_index(part)?);
                        }
                    }
                    poly.push(v);
                }
                if poly.len() < 3 {
                    return None;
                }
                let have = [c.verts.len() as i64, c.texcoords, c.normals];
                for k in 0..3 {
                    if most[k] > 0 {
                        c.excess[k] = c.excess[k].max(i64::from(most[k]) - have[k]);
                    }
                }
                for k in 1..poly.len() - 1 {
                    c.faces.push([poly[0], poly[k], poly[k + 1]]);
                }
            }
            b"vt" | b"vn" => {
                // tobj needs 2 (vt) or 3 (vn) numbers and ignores any more.
                let n = if key == b"vt" { 2 } else { 3 };
                for _ in 0..n {
                    std::str::from_utf8(words.next()?)
                        .ok()?
                        .parse::<f32>()
                        .ok()?;
                }
                if key == b"vt" {
                    c.texcoords += 1;
                } else {
                    c.normals += 1;
                }
            }
            b"usemtl" => {
                // tobj takes the name after the first space and fails when it is blank.
                let name = line
                    .iter()
                    .position(|&b| b == b' ')
                    .map_or(&[][..], |i| &line[i + 1..]);
                if !name.iter().any(u8::is_ascii_graphic) {
                    return None;
                }
            }
            b"s" | b"o" | b"g" | b"mtllib" => {}
            k if k.first() == Some(&b'#') => {}
            _ => return None,
        }
    }
    Some(c)
}

/// A positive 1-based index (negative, relative ones are left to tobj).
fn parse_index(w: &[u8]) -> Option<u32> {
    if w.is_empty() || w.len() > 9 {
        return None;
    }
    let mut v = 0u32;
    for &b in w {
        if !b.is_ascii_digit() {
            return None;
        }
        v = v * 10 + u32::from(b - b'0');
    }
    (v > 0).then_some(v)
}
