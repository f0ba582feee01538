//! `#` comments survive read → write → read: each is written back where the parser attaches
//! it again, and one that cannot be kept is reported with its location.

use std::path::Path;

use tracelab_core::{MeshCache, Scene, Severity, load_scene, parse_scene, write_scene};

fn parse(text: &str) -> (Scene, Vec<String>) {
    let out = parse_scene(text.as_bytes(), "c.txt", None, &mut MeshCache::new());
    let warnings = out.diagnostics.warnings().map(|d| d.to_string()).collect();
    let scene = out
        .scene
        .unwrap_or_else(|| panic!("does not parse:\n{}", out.diagnostics));
    (scene, warnings)
}

/// Every comment line of `text`, trimmed, in file order.
fn comment_lines(text: &str) -> Vec<&str> {
    text.lines()
        .map(str::trim)
        .filter(|l| l.starts_with('#'))
        .collect()
}

const EVERYWHERE: &str = "# header 1
# header 2
PerspectiveCamera {
    # cam center
    center 0 0 10
    direction 0 0 -1 # trailing on direction
    up 0 1 0
    angle 30
    # cam end
}
# before lights
Lights {
    # before numLights
    numLights 1
    # before light
    DirectionalLight {
        # light color
        color 1 1 1
        direction 0 0 -1
        # light end
    }
    # lights end
}
# before background
Background {
    # bg ambient
    ambientLight 0.1 0.1 0.1
    color 0 0 0
}
# before materials
Materials {
    numMaterials 2
    # mat 0
    PhongMaterial {
        diffuseColor 1 0 0
        # mat exponent { with braces } and # hashes
        exponent 20
    }
    Material { diffuseColor 0 1 0 # mat 1 end
    }
    # materials end
}
# before group
Group {
    # before numObjects
    numObjects 3
    # before MaterialIndex
    MaterialIndex 0
    # between MaterialIndex and Sphere
    Sphere {
        center 0 0 0
        # radius
        radius 1
    }
    # transform
    Transform {
        # op 0
        Translate 1 0 0
        XRotate 30
        # op 2
        Scale 1 2 1
        # the child
        Group {
            numObjects 1
            MaterialIndex 1
            Triangle { vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 }
            # inner group end
        }
        # transform end
    }
    Union {
        # operand a
        Box { min -1 -1 -1 max 1 1 1 }
        Sphere { center 0 0 0 radius 1.2 }
        # union end
    }
    # group end
}
# end of file
";

#[test]
fn comments_everywhere_survive_a_round_trip() {
    let (scene, warnings) = parse(EVERYWHERE);
    assert!(warnings.is_empty(), "{warnings:?}");
    let text = write_scene(&scene);
    let mut want = comment_lines(EVERYWHERE);
    // A trailing comment is written on a line of its own, before what follows it.
    want.push("# trailing on direction");
    want.push("# mat 1 end");
    let mut got = comment_lines(&text);
    for w in &want {
        assert!(got.contains(w), "{w} was lost:\n{text}");
    }
    let n = got.len();
    got.sort();
    got.dedup();
    assert_eq!(got.len(), n, "a comment was written twice:\n{text}");
    let (back, _) = parse(&text);
    assert_eq!(
        back, scene,
        "the written text reads back to a different scene:\n{text}"
    );
    assert_eq!(write_scene(&back), text, "writing is canonical");
}

#[test]
fn comments_stay_with_what_follows_them_at_its_indentation() {
    let (scene, _) = parse(EVERYWHERE);
    let text = write_scene(&scene);
    assert!(
        text.starts_with(
            "# header 1\n# header 2\nPerspectiveCamera {\n    # cam center\n    center 0 0 10\n"
        ),
        "{text}"
    );
    for (comment, next) in [
        (
            "    # before MaterialIndex\n    # between MaterialIndex and Sphere\n",
            "    MaterialIndex 0\n    Sphere {",
        ),
        ("        # radius\n", "        radius 1\n"),
        ("        # op 2\n", "        Scale 1 2 1\n"),
        ("        # light color\n", "        color 1 1 1\n"),
        ("            # inner group end\n", "        }\n"),
        ("    # group end\n", "}\n# end of file\n"),
    ] {
        assert!(
            text.contains(&format!("{comment}{next}")),
            "expected {comment:?} before {next:?}:\n{text}"
        );
    }
}

#[test]
fn the_lecture_header_comment_is_written_back() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/lecture/simple_scene.txt");
    let original = std::fs::read_to_string(&path).expect("lecture scene");
    let (scene, _) = load_scene(&path, &mut MeshCache::new())
        .into_result()
        .expect("parses");
    let text = write_scene(&scene);
    let header: String = original
        .lines()
        .take_while(|l| l.starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(!header.is_empty());
    assert!(
        text.starts_with(&format!("{header}OrthographicCamera {{\n")),
        "{text}"
    );
}

#[test]
fn a_comment_inside_a_value_is_reported_as_lost_with_its_location() {
    let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }
Group {
    numObjects 1
    Sphere {
        center 0 0 0
        radius # in the way
        1
    }
}
";
    let out = parse_scene(text.as_bytes(), "c.txt", None, &mut MeshCache::new());
    let lost: Vec<String> = out
        .diagnostics
        .0
        .iter()
        .filter(|d| d.severity == Severity::Warning && d.message.contains("comment"))
        .map(|d| d.to_string())
        .collect();
    assert_eq!(lost.len(), 1, "{}", out.diagnostics);
    assert!(lost[0].starts_with("c.txt:6:16: "), "{}", lost[0]);
    assert_eq!(out.lost_comments.len(), 1);
    let scene = out.scene.expect("still a scene");
    assert!(!write_scene(&scene).contains("in the way"));
}

/// A comment dropped between any two tokens of a scene never breaks the round trip: the
/// scene read back from the writer's text equals the scene read, comments included.
#[test]
fn a_comment_anywhere_round_trips_or_is_reported() {
    let base: Vec<&str> = EVERYWHERE
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .collect::<Vec<_>>()
        .join("\n")
        .leak()
        .split_inclusive(char::is_whitespace)
        .collect();
    for i in 0..=base.len() {
        let mut text: String = base[..i].concat();
        text.push_str("\n# inserted {here}\n");
        text.push_str(&base[i..].concat());
        let out = parse_scene(text.as_bytes(), "c.txt", None, &mut MeshCache::new());
        let Some(scene) = out.scene else { continue };
        let written = write_scene(&scene);
        assert_eq!(
            written.contains("# inserted {here}"),
            out.lost_comments.is_empty(),
            "kept or reported, at {i}:\n{text}"
        );
        let (back, _) = parse(&written);
        assert_eq!(back, scene, "at {i}:\n{text}\n---\n{written}");
    }
}
