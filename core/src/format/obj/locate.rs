//! Where and why tobj refuses an OBJ file. tobj's errors name neither the line nor, in
//! words a user would know, the fault ("color parse error" for a comment after a vertex), so
//! the text is read again here with tobj's own rules, line by line, and the first line it
//! stops at is named: `m.obj:LINE: what is wrong`.
//!
//! The rules mirrored (tobj 4, with points and lines ignored): a line fails when it cannot
//! be parsed (`v`, `vt`, `vn`, `f`/`l`, `usemtl`); a face's indices are checked only when
//! its group ends (the next `o`/`g` after faces, and the end of the file), against every
//! vertex, texture coordinate, normal and colour read by then.

/// tobj's "no index given" (also what index 0 becomes for a texture or normal index).
const MISSING: usize = usize::MAX;

/// One face waiting for its group's end: its line, and each corner's (v, vt, vn) as tobj
/// stores them, beside the words as written.
struct Face<'a> {
    line: usize,
    /// Vertices before the face, for the message about relative indices.
    vertices_before: usize,
    corners: Vec<([usize; 3], &'a str)>,
}

/// Counts read so far (tobj's arrays, in entries), and the faces of the open group.
#[derive(Default)]
struct Read<'a> {
    vertices: usize,
    colours: usize,
    texcoords: usize,
    normals: usize,
    faces: Vec<Face<'a>>,
}

/// `name:LINE: what is wrong` for the first line where tobj stops, or None if none is found.
pub(super) fn tobj_refusal(bytes: &[u8], name: &str) -> Option<String> {
    let mut read = Read::default();
    let mut lines = bytes.split(|&b| b == b'\n').enumerate().peekable();
    while let Some((i, raw)) = lines.next() {
        // `BufRead::lines`: the last piece after a final newline is no line.
        if raw.is_empty() && lines.peek().is_none() {
            break;
        }
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let Ok(line) = std::str::from_utf8(raw) else {
            return Some(format!(
                "{name}:{}: not a text OBJ file: bytes that are not UTF-8",
                i + 1
            ));
        };
        if let Some((line, why)) = line_fault(line, i + 1, &mut read) {
            return Some(format!("{name}:{line}: {why}"));
        }
    }
    group_end(&read).map(|(line, why)| format!("{name}:{line}: {why}"))
}

/// What is wrong with one line, read in tobj's way, as (the line to name, why); the end of
/// a group names the face that refers to something not read.
fn line_fault<'a>(line: &'a str, number: usize, read: &mut Read<'a>) -> Option<(usize, String)> {
    let here = |why: String| Some((number, why));
    let mut words = line.split_whitespace();
    let quoted = || format!("\"{}\"", line.trim().escape_debug());
    match words.next() {
        Some("v") => {
            if !numbers(&mut words, 3) {
                return here(format!("bad vertex {}: expected three numbers", quoted()));
            }
            read.vertices += 1;
            let rest: Vec<&str> = words.collect();
            let comment = if rest.iter().any(|w| w.starts_with('#')) {
                " (a # comment must be on a line of its own)"
            } else {
                ""
            };
            match rest.len() {
                0 => {}
                1 => match rest[0].parse::<f32>() {
                    Err(_) => {
                        return here(format!(
                            "bad vertex {}: the fourth value (w) is not a number{comment}",
                            quoted()
                        ));
                    }
                    Ok(0.0) => {
                        return here(format!("vertex {} has w = 0", quoted()));
                    }
                    Ok(_) => {}
                },
                3 => {
                    // Colours: tobj keeps the leading ones that are numbers.
                    read.colours += rest.iter().take_while(|w| w.parse::<f32>().is_ok()).count();
                }
                n => {
                    return here(format!(
                        "vertex {} has {} values: expected x y z, x y z w or x y z r g b{comment}",
                        quoted(),
                        n + 3
                    ));
                }
            }
        }
        Some("vt") => {
            if !numbers(&mut words, 2) {
                return here(format!(
                    "bad texture coordinate {}: expected two numbers",
                    quoted()
                ));
            }
            read.texcoords += 1;
        }
        Some("vn") => {
            if !numbers(&mut words, 3) {
                return here(format!("bad normal {}: expected three numbers", quoted()));
            }
            read.normals += 1;
        }
        Some("f" | "l") => {
            let sizes = [read.vertices, read.texcoords, read.normals];
            let mut corners = Vec::new();
            for w in words {
                let mut idx = [MISSING; 3];
                for (k, part) in w.split('/').enumerate() {
                    if part.is_empty() {
                        continue;
                    }
                    let Ok(x) = part.parse::<isize>() else {
                        return here(format!("bad face index \"{}\"", w.escape_debug()));
                    };
                    let Some(slot) = idx.get_mut(k) else {
                        return here(format!(
                            "bad face index \"{}\": at most vertex/texture/normal",
                            w.escape_debug()
                        ));
                    };
                    // tobj's arithmetic: relative indices count back from what was read.
                    *slot = if x < 0 {
                        (sizes[k] as isize).wrapping_add(x) as usize
                    } else {
                        (x - 1) as usize
                    };
                }
                corners.push((idx, w));
            }
            // One or two corners make a point or a line, which are ignored.
            if corners.is_empty() || corners.len() >= 3 {
                read.faces.push(Face {
                    line: number,
                    vertices_before: read.vertices,
                    corners,
                });
            }
        }
        Some("o" | "g") => {
            // Named at the face, though tobj finds it only here.
            if let Some(fault) = group_end(read) {
                return Some(fault);
            }
            read.faces.clear();
        }
        Some("usemtl") => {
            let name = line.split_once(' ').map_or("", |(_, n)| n.trim());
            if name.is_empty() {
                return here("usemtl without a material name".into());
            }
        }
        _ => {}
    }
    None
}

/// `n` words that parse as numbers (tobj's `parse_floatn`; more are not its business).
fn numbers(words: &mut std::str::SplitWhitespace<'_>, n: usize) -> bool {
    words.take(n).filter(|w| w.parse::<f32>().is_ok()).count() == n
}

/// The first face of the open group that refers to something not read: (its line, why).
fn group_end(read: &Read<'_>) -> Option<(usize, String)> {
    for f in &read.faces {
        if f.corners.is_empty() {
            return Some((f.line, "face without vertices".into()));
        }
        for &([v, vt, vn], word) in &f.corners {
            let word = word.escape_debug();
            let index = word.to_string();
            let index = index.split('/').next().unwrap_or("");
            if v >= read.vertices {
                let why = if index.starts_with('-') {
                    format!(
                        "face refers to vertex {index}, counting back past the first of the {} vertices before it",
                        f.vertices_before
                    )
                } else if v == MISSING {
                    format!("face refers to vertex \"{word}\": vertex indices start at 1")
                } else {
                    format!(
                        "face refers to vertex {index}, but the file has only {} vertices",
                        read.vertices
                    )
                };
                return Some((f.line, why));
            }
            if read.colours > 0 && v * 3 + 2 >= read.colours {
                return Some((
                    f.line,
                    format!(
                        "face uses vertex {}, which has no colour while others have: give every vertex r g b, or none",
                        v + 1
                    ),
                ));
            }
            if read.texcoords > 0 && vt != MISSING && vt >= read.texcoords {
                return Some((
                    f.line,
                    format!(
                        "face \"{word}\" refers to a texture coordinate that does not exist (the file has {})",
                        read.texcoords
                    ),
                ));
            }
            if read.normals > 0 && vn != MISSING && vn >= read.normals {
                return Some((
                    f.line,
                    format!(
                        "face \"{word}\" refers to a normal that does not exist (the file has {})",
                        read.normals
                    ),
                ));
            }
        }
    }
    None
}

/// `name:LINE: …` for the first vertex that is not a finite number (`1e39`, `inf`, or a
/// division by a tiny w), as both readers read it.
pub(super) fn non_finite_vertex(bytes: &[u8], name: &str) -> String {
    let text = String::from_utf8_lossy(bytes);
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        let xyz: Vec<f32> = words
            .by_ref()
            .take(3)
            .filter_map(|w| w.parse().ok())
            .collect();
        let rest: Vec<&str> = words.collect();
        let w = match rest.as_slice() {
            [w] => w.parse::<f32>().unwrap_or(1.0),
            _ => 1.0,
        };
        if xyz.iter().any(|c| !(c / w).is_finite()) {
            return format!(
                "{name}:{}: vertex \"{}\" is not a finite number (f32 holds up to about 3.4e38)",
                i + 1,
                line.trim().escape_debug()
            );
        }
    }
    format!("{name}: a vertex is not a finite number")
}

/// What tobj refused, in tracelab's words, for the rare case the scan above finds no line.
pub(super) fn unlocated(e: &tobj::LoadError, name: &str) -> String {
    use tobj::LoadError as E;
    let what = match e {
        E::PositionParseError | E::ScalingByZeroError | E::ColorParseError => {
            "a vertex is not three numbers (x y z, x y z w or x y z r g b)"
        }
        E::TexcoordParseError => "a texture coordinate is not two numbers",
        E::NormalParseError => "a normal is not three numbers",
        E::FaceParseError | E::InvalidPolygon => "a face is not a list of vertex indices",
        E::FaceVertexOutOfBounds => "a face refers to a vertex that does not exist",
        E::FaceTexCoordOutOfBounds => "a face refers to a texture coordinate that does not exist",
        E::FaceNormalOutOfBounds => "a face refers to a normal that does not exist",
        E::FaceColorOutOfBounds => "a face uses a vertex without a colour while others have one",
        E::MaterialParseError => "usemtl without a material name",
        E::ReadError => "not a text OBJ file",
        _ => "not an OBJ file tracelab can read",
    };
    format!("{name}: {what} (its line could not be found)")
}
