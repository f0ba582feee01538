//! A parallel reader for the plain OBJ files scanned meshes come as (`v x y z` and
//! `f a b c ...` with positive indices, optionally `a/t/n`). Anything else it does not
//! understand makes it give up, and the caller reads the file with tobj, which stays the
//! reference. It exists for speed: tobj spends ~1 s on the 871k-triangle dragon.

use glam::Vec3;
use rayon::prelude::*;

/// Below this size one thread reads the whole file.
const CHUNK: usize = 1 << 19;

#[derive(Default)]
struct Chunk {
    verts: Vec<Vec3>,
    /// 1-based vertex indices as written.
    faces: Vec<[u32; 3]>,
    /// Largest (index − vertices read so far in this chunk) over the chunk's faces: the
    /// chunk is valid when the vertices of all earlier chunks cover it.
    excess: i64,
}

/// Positions and triangles (fan-triangulated, as tobj does), or None when the file needs tobj.
pub fn parse(bytes: &[u8]) -> Option<(Vec<Vec3>, Vec<[u32; 3]>)> {
    let chunks = split_lines(bytes, CHUNK);
    let parsed: Vec<Chunk> = chunks
        .par_iter()
        .map(|&(a, b)| parse_chunk(&bytes[a..b]))
        .collect::<Option<_>>()?;
    let mut base = 0i64;
    for c in &parsed {
        if c.excess > base {
            return None;
        }
        base += c.verts.len() as i64;
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
        excess: i64::MIN,
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
                for w in words {
                    let idx = w.split(|&b| b == b'/').next()?;
                    poly.push(parse_index(idx)?);
                }
                if poly.len() < 3 {
                    return None;
                }
                let nv = c.verts.len() as i64;
                let most = poly.iter().copied().max().unwrap_or(0);
                c.excess = c.excess.max(i64::from(most) - nv);
                for k in 1..poly.len() - 1 {
                    c.faces.push([poly[0], poly[k], poly[k + 1]]);
                }
            }
            b"vn" | b"vt" | b"s" | b"o" | b"g" | b"usemtl" | b"mtllib" => {}
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
