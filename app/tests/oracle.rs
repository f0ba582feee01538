//! The student's oracle: `tracelab inspect` (one pixel's story, as text and as the JSON of
//! docs/inspect-json.md) and `tracelab diff` (a student's image against the reference for a
//! course command line). Every expected number here is computed in the test from the scene's
//! own numbers (f64, by hand-written formulas), not taken from tracelab.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::repo;
use common::tracelab;
use glam::{DMat3, DMat4, DVec3};
use serde_json::Value;

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tracelab-oracle-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn inspect_json(scene: &str, args: &[&str]) -> Value {
    let path = repo().join(scene);
    let mut all = vec!["inspect", path.to_str().expect("utf-8")];
    all.extend_from_slice(args);
    all.push("--json");
    let o = tracelab(&all, &repo());
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_slice(&o.stdout).expect("valid JSON")
}

fn vec3(v: &Value) -> DVec3 {
    let a = v.as_array().expect("array of 3");
    assert_eq!(a.len(), 3);
    DVec3::new(
        a[0].as_f64().expect("n"),
        a[1].as_f64().expect("n"),
        a[2].as_f64().expect("n"),
    )
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// A JSON 3×3 (rows) as a matrix.
fn mat3(v: &Value) -> DMat3 {
    let r: Vec<DVec3> = v.as_array().expect("rows").iter().map(vec3).collect();
    DMat3::from_cols(r[0], r[1], r[2]).transpose()
}

fn close(a: DVec3, b: DVec3, tol: f64, what: &str) {
    assert!((a - b).length() < tol, "{what}: {a} vs {b}");
}

fn close_m(a: DMat3, b: DMat3, tol: f64, what: &str) {
    let d = (a - b)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(d < tol, "{what}: {a} vs {b}");
}

#[test]
fn inspect_json_matches_a_hand_computed_sheared_sphere_pixel() {
    // scenes/sheared_sphere.txt, the second sphere: Translate 1.2 0 0, Matrix (x += 0.6 y),
    // Scale 0.5 1.5 0.8 on the unit sphere; orthographic camera at z = 10, size 5, looking
    // down −z; light from direction (−0.5, −0.5, −1), colour 0.9; ambient 0.1; k_d (0.9, 0.3, 0.2).
    let j = inspect_json(
        "scenes/sheared_sphere.txt",
        &["--size", "40", "40", "--pixel", "28", "18"],
    );
    assert_eq!(j["schema"], "tracelab-inspect/1");
    assert_eq!(j["pixel"]["x"], 28);
    assert_eq!(j["pixel"]["row"], 18);
    // Pixel centre: ((28.5/40) − ½)·5 and, rows from the top, ((40 − 1 − 18 + ½)/40 − ½)·5.
    let o = DVec3::new((28.5 / 40.0 - 0.5) * 5.0, (21.5 / 40.0 - 0.5) * 5.0, 10.0);
    let d = DVec3::NEG_Z;
    close(vec3(&j["world_ray"]["origin"]), o, 1e-6, "origin");
    close(vec3(&j["world_ray"]["direction"]), d, 1e-7, "direction");

    let lin = DMat3::from_cols(
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::new(0.9, 1.5, 0.0),
        DVec3::new(0.0, 0.0, 0.8),
    );
    let m = DMat4::from_cols(
        lin.x_axis.extend(0.0),
        lin.y_axis.extend(0.0),
        lin.z_axis.extend(0.0),
        DVec3::new(1.2, 0.0, 0.0).extend(1.0),
    );
    let inv = m.inverse();
    let h = &j["hit"];
    assert_eq!(h["node"]["kind"], "Sphere");
    let path = h["path"].as_array().expect("path");
    let labels: Vec<&str> = path
        .iter()
        .map(|s| s["node"]["label"].as_str().expect("label"))
        .collect();
    assert_eq!(
        labels,
        [
            "Group (2)",
            "Transform: Translate(1.2, 0, 0) · Matrix(4×4) · Scale(0.5, 1.5, 0.8)",
            "Sphere: (0, 0, 0) r 1"
        ]
    );
    let t = &path[1]["transform"];
    close_m(mat3(&t["M"]["linear"]), lin, 1e-6, "M");
    close(
        vec3(&t["M"]["translation"]),
        DVec3::new(1.2, 0.0, 0.0),
        1e-6,
        "M translation",
    );
    close_m(
        mat3(&t["M_inverse"]["linear"]),
        DMat3::from_mat4(inv),
        1e-6,
        "M⁻¹",
    );
    close(
        vec3(&t["M_inverse"]["translation"]),
        inv.w_axis.truncate(),
        1e-6,
        "M⁻¹ translation",
    );
    close_m(
        mat3(&t["M_inverse_transpose"]),
        DMat3::from_mat4(inv).transpose(),
        1e-6,
        "(M⁻¹)ᵀ",
    );
    assert_eq!(t["similitude"]["is_similitude"], false);
    assert!(t["similitude"]["lambda"].is_null());
    let kinds: Vec<&str> = t["similitude"]["breaks"]
        .as_array()
        .expect("breaks")
        .iter()
        .map(|b| b["kind"].as_str().expect("kind"))
        .collect();
    assert_eq!(kinds, ["non_uniform_scale", "shear"]);
    assert!(path[0]["transform"].is_null() && path[2]["transform"].is_null());

    // Object space: o' = M⁻¹o, d' = M⁻¹d (not renormalised); |o' + t d'|² = 1, nearer root.
    let (oo, dd) = (inv.transform_point3(o), inv.transform_vector3(d));
    close(vec3(&path[2]["ray"]["origin"]), oo, 1e-5, "object origin");
    close(
        vec3(&path[2]["ray"]["direction"]),
        dd,
        1e-6,
        "object direction",
    );
    let (a, b, c) = (dd.dot(dd), 2.0 * oo.dot(dd), oo.dot(oo) - 1.0);
    let t_hit = (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
    assert!(
        (num(&h["t"]["world"]) - t_hit).abs() < 1e-4,
        "{} vs {t_hit}",
        h["t"]["world"]
    );
    assert!(
        (num(&h["t"]["object"]) - t_hit).abs() < 1e-4,
        "unnormalised: the same t"
    );
    assert_eq!(h["t"]["used_is"], "world");
    assert!((num(&h["t"]["object_direction_length"]) - dd.length()).abs() < 1e-6);
    let p_obj = oo + dd * t_hit;
    close(vec3(&h["point_object"]), p_obj, 1e-4, "object point");
    close(vec3(&h["point_world"]), o + d * t_hit, 1e-4, "world point");
    // Unit sphere: the object normal is the point; world normals by both rules.
    close(vec3(&h["normal"]["object"]), p_obj, 1e-4, "object normal");
    let n_good = (DMat3::from_mat4(inv).transpose() * p_obj).normalize();
    let n_bad = (lin * p_obj).normalize();
    close(vec3(&h["normal"]["world_correct"]), n_good, 1e-4, "(M⁻¹)ᵀn");
    close(vec3(&h["normal"]["world_incorrect"]), n_bad, 1e-4, "Mn");
    let angle = n_good.angle_between(n_bad).to_degrees();
    assert!(
        (num(&h["normal"]["angle_degrees"]) - angle).abs() < 1e-2,
        "{angle}"
    );
    // Shading: ambient·k_d + max(L·N, 0)·c·k_d, L toward the light.
    let kd = DVec3::new(0.9, 0.3, 0.2);
    let l = -DVec3::new(-0.5, -0.5, -1.0).normalize();
    let ln = l.dot(n_good);
    let sh = &h["shading"];
    assert!((num(&sh["lights"][0]["l_dot_n"]) - ln).abs() < 1e-4);
    let color = 0.1 * kd + ln.max(0.0) * 0.9 * kd;
    close(vec3(&sh["color"]), color, 1e-4, "colour");
    close(vec3(&j["color"]), color, 1e-4, "pixel colour");
    let bytes: Vec<u64> = j["rgb8"]
        .as_array()
        .expect("rgb8")
        .iter()
        .map(|v| v.as_u64().expect("byte"))
        .collect();
    let expect: Vec<u64> = color
        .to_array()
        .iter()
        .map(|c| (c * 255.0).floor() as u64)
        .collect();
    assert_eq!(bytes, expect);
    // And the rendered image has those bytes at that pixel.
    let dir = temp_dir("inspect-render");
    let scene = repo().join("scenes/sheared_sphere.txt");
    let o = tracelab(
        &[
            "render",
            scene.to_str().expect("utf-8"),
            "--size",
            "40",
            "40",
            "--output",
            "a.png",
        ],
        &dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(dir.join("a.png")).expect("png").to_rgb8();
    assert_eq!(img.get_pixel(28, 18).0.map(u64::from).to_vec(), bytes);
}

#[test]
fn inspect_json_says_which_t_the_bug_keeps() {
    // scenes/lecture/depth_t.txt at 60×60, pixel (36, 29): screen (0.65, 0.05). The blue
    // sphere (world radius 2 at (−0.6, 0, −4), UniformScale 4) is entered at
    // t = 14 − √(4 − 1.25² − 0.05²); its normalised object ray runs a quarter as far.
    let (x, y) = (0.65f64, 0.05f64);
    let t_blue = 14.0 - (4.0 - (x + 0.6).powi(2) - y * y).sqrt();
    let t_red = 10.0 - (1.0 - (x - 0.6).powi(2) - y * y).sqrt();
    let good = inspect_json(
        "scenes/lecture/depth_t.txt",
        &["--size", "60", "60", "--pixel", "36", "29"],
    );
    assert!((num(&good["hit"]["t"]["world"]) - t_red).abs() < 1e-4);
    let normalized = inspect_json(
        "scenes/lecture/depth_t.txt",
        &[
            "--size",
            "60",
            "60",
            "--pixel",
            "36",
            "29",
            "--object-rays",
            "normalized",
        ],
    );
    let tn = &normalized["hit"]["t"];
    assert!((num(&tn["world"]) - t_red).abs() < 1e-4 && (num(&tn["used"]) - t_red).abs() < 1e-4);
    // UniformScale 0.5: |M⁻¹d| = 2, so the unit-direction object ray runs twice as far.
    assert!((num(&tn["object"]) - 2.0 * t_red).abs() < 1e-4, "{tn}");
    assert!((vec3(&normalized["hit"]["traced_ray"]["direction"]).length() - 1.0).abs() < 1e-6);
    let bug = inspect_json(
        "scenes/lecture/depth_t.txt",
        &[
            "--size",
            "60",
            "60",
            "--pixel",
            "36",
            "29",
            "--object-rays",
            "normalized-no-rescale",
        ],
    );
    assert_eq!(bug["settings"]["object_rays"], "normalized-no-rescale");
    let tb = &bug["hit"]["t"];
    assert_eq!(tb["used_is"], "object");
    assert!((num(&tb["world"]) - t_blue).abs() < 1e-4, "{tb}");
    assert!((num(&tb["used"]) - t_blue / 4.0).abs() < 1e-4, "{tb}");
    assert!((num(&tb["object"]) - t_blue / 4.0).abs() < 1e-4, "{tb}");
    // UniformScale 4 is a similitude: (M⁻¹)ᵀ = M/16.
    let s = &bug["hit"]["world_from_object"]["similitude"];
    assert_eq!(s["is_similitude"], true);
    assert!((num(&s["lambda"]) - 1.0 / 16.0).abs() < 1e-12, "{s}");
}

#[test]
fn inspect_text_names_rows_from_the_top_and_refuses_pixels_outside() {
    let help = tracelab(&["inspect", "--help"], &repo());
    assert!(help.status.success());
    assert!(String::from_utf8_lossy(&help.stdout).contains("from the TOP"));
    let scene = repo().join("scenes/sheared_sphere.txt");
    let scene = scene.to_str().expect("utf-8");
    let o = tracelab(
        &[
            "inspect", scene, "--size", "40", "40", "--pixel", "28", "18",
        ],
        &repo(),
    );
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for want in [
        "row from the top",
        "M⁻¹",
        "(M⁻¹)ᵀ",
        "not a similitude",
        "world by M",
        "sum",
    ] {
        assert!(text.contains(want), "{want} missing:\n{text}");
    }
    let o = tracelab(
        &["inspect", scene, "--size", "40", "40", "--pixel", "40", "0"],
        &repo(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("outside the 40×40 image"),
        "{}",
        stderr(&o)
    );
    let o = tracelab(
        &[
            "inspect",
            "no-such.txt",
            "--size",
            "4",
            "4",
            "--pixel",
            "0",
            "0",
        ],
        &repo(),
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("no-such.txt"), "{}", stderr(&o));
    let o = tracelab(
        &["inspect", scene, "--size", "0", "4", "--pixel", "0", "0"],
        &repo(),
    );
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn inspect_prints_the_bytes_each_image_holds_as_the_render_writes_them() {
    // Inside a sphere of radius 5: the corners see its back faces, the centre the small
    // sphere's front. Depth range 2..6 puts the front sphere (t ≈ 2.5) mid-grey.
    let dir = temp_dir("inspect-bytes");
    let scene = repo().join("scenes/inside_sphere.txt");
    let scene = scene.to_str().expect("utf-8");
    for shade_back in [false, true] {
        let mut line = vec![
            "-input", scene, "-size", "30", "30", "-output", "c.png", "-normals", "n.png",
            "-depth", "2", "6", "d.png",
        ];
        if shade_back {
            line.push("-shade_back");
        }
        let o = tracelab(&line, &dir);
        assert!(o.status.success(), "{}", stderr(&o));
        let read = |f: &str| image::open(dir.join(f)).expect("image").to_rgb8();
        let (c, n, d) = (read("c.png"), read("n.png"), read("d.png"));
        let mut backs = 0;
        for (x, row) in [(0u32, 0u32), (15, 15), (3, 20), (29, 29), (16, 12)] {
            let (xs, rs) = (x.to_string(), row.to_string());
            let mut args = vec![
                "--size", "30", "30", "--pixel", &xs, &rs, "--depth", "2", "6",
            ];
            if shade_back {
                args.push("--shade-back");
            }
            let j = inspect_json("scenes/inside_sphere.txt", &args);
            let bytes = |v: &Value| -> Vec<u8> {
                v.as_array()
                    .expect("bytes")
                    .iter()
                    .map(|b| b.as_u64().expect("byte") as u8)
                    .collect()
            };
            let at = |img: &image::RgbImage| img.get_pixel(x, row).0.to_vec();
            let i = &j["images"];
            assert_eq!(bytes(&i["color"]), at(&c), "colour at {x},{row}");
            assert_eq!(bytes(&i["normals"]), at(&n), "normals at {x},{row}");
            assert_eq!(bytes(&i["depth"]["bytes"]), at(&d), "depth at {x},{row}");
            assert_eq!(num(&i["depth"]["min"]), 2.0);
            let back = j["hit"]["shading"]["back_facing"] == true;
            backs += usize::from(back);
            if back {
                // Documented as c_ambient·k_d, back face or not: 0.2 × (0.9, 0.9, 0.6).
                let amb = vec3(&j["hit"]["shading"]["ambient"]);
                close(amb, DVec3::new(0.18, 0.18, 0.12), 1e-6, "ambient");
                assert_eq!(bytes(&i["color"]) == [0, 0, 0], !shade_back);
            }
        }
        // The corners are the big sphere's inside; the centre is the small one's front.
        assert!((2..5).contains(&backs), "{backs} back faces");
    }
    // Text: the same bytes; without --depth, how to get the depth byte.
    let o = tracelab(
        &["inspect", scene, "--size", "30", "30", "--pixel", "0", "0"],
        &repo(),
    );
    let text = String::from_utf8_lossy(&o.stdout);
    for want in [
        "drawn black without --shade-back",
        "ambient·k_d            (0.18000, 0.18000, 0.12000)",
        "each image here: colour [0, 0, 0], normals [",
        "depth: give --depth MIN MAX",
    ] {
        assert!(text.contains(want), "{want} missing:\n{text}");
    }
    for bad in ["nan", "1e39", "-inf", "x", ""] {
        let o = tracelab(
            &[
                "inspect", scene, "--size", "30", "30", "--pixel", "0", "0", "--depth", "2", bad,
            ],
            &repo(),
        );
        assert_eq!(o.status.code(), Some(2), "--depth 2 {bad:?}");
        assert!(stderr(&o).contains("--depth"), "{}", stderr(&o));
    }
}

/// Renders the course line with tracelab into `dir` (the "student's" outputs), then runs
/// `tracelab diff IMAGE -- LINE`.
fn course_line(scene: &Path) -> Vec<String> {
    let s = scene.to_str().expect("utf-8").to_string();
    [
        "-input", &s, "-size", "50", "40", "-output", "out.png", "-normals", "n.png", "-depth",
        "8", "11", "d.png",
    ]
    .map(String::from)
    .to_vec()
}

fn diff(dir: &Path, image: &str, line: &[String], extra: &[&str]) -> Output {
    let mut args = vec!["diff", image];
    args.extend_from_slice(extra);
    args.push("--");
    args.extend(line.iter().map(String::as_str));
    tracelab(&args, dir)
}

#[test]
fn diff_of_a_perfect_image_matches_and_leaves_the_students_files_alone() {
    let dir = temp_dir("diff-perfect");
    let line = course_line(&repo().join("scenes/sheared_sphere.txt"));
    let args: Vec<&str> = line.iter().map(String::as_str).collect();
    assert!(tracelab(&args, &dir).status.success());
    std::fs::copy(dir.join("out.png"), dir.join("mine.png")).expect("copy");
    let before: Vec<Vec<u8>> = ["out.png", "n.png", "d.png"]
        .iter()
        .map(|f| std::fs::read(dir.join(f)).expect("read"))
        .collect();
    let o = diff(&dir, "mine.png", &line, &[]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}{}", stderr(&o));
    for want in [
        "colour mine.png: 0 of 2,000 pixels off by more than 2/255 (0.00%; the limit is < 1%)",
        "normals n.png: 0 of 2,000 pixels off",
        "depth d.png: 0 of 2,000 pixels off",
        "matches",
    ] {
        assert!(out.contains(want), "{want} missing:\n{out}");
    }
    let after: Vec<Vec<u8>> = ["out.png", "n.png", "d.png"]
        .iter()
        .map(|f| std::fs::read(dir.join(f)).expect("read"))
        .collect();
    assert_eq!(
        before, after,
        "diff must not write the files the line names"
    );
    // The heat map of a perfect image is the reference, dimmed to a quarter, in grey.
    let map = image::open(dir.join("mine.diff.png"))
        .expect("heat map")
        .to_rgb8();
    let reference = image::open(dir.join("out.png")).expect("ref").to_rgb8();
    for (m, r) in map.pixels().zip(reference.pixels()) {
        let lum = (u32::from(r[0]) * 3 + u32::from(r[1]) * 6 + u32::from(r[2])) / 10;
        assert_eq!(m.0, [(lum / 4) as u8; 3]);
    }
}

#[test]
fn diff_of_a_slightly_wrong_image_names_the_wrong_pixels_and_still_matches() {
    let dir = temp_dir("diff-slight");
    let line = course_line(&repo().join("scenes/sheared_sphere.txt"));
    let args: Vec<&str> = line.iter().map(String::as_str).collect();
    assert!(tracelab(&args, &dir).status.success());
    // Six pixels off by 30 in red, one by 90: 7 of 2000 is 0.35%, under the 1% allowed.
    let mut img = image::open(dir.join("out.png")).expect("out").to_rgb8();
    let spots = [
        (10u32, 5u32, 30u8),
        (11, 5, 30),
        (12, 5, 30),
        (30, 20, 30),
        (31, 20, 30),
        (32, 20, 30),
        (36, 21, 90),
    ];
    for &(x, row, by) in &spots {
        let p = img.get_pixel_mut(x, row);
        p[0] = if p[0] >= by { p[0] - by } else { p[0] + by };
    }
    img.save(dir.join("mine.png")).expect("save");
    let o = diff(&dir, "mine.png", &line, &["--regions", "2"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}");
    assert!(
        out.contains("7 of 2,000 pixels off by more than 2/255 (0.35%; the limit is < 1%), largest difference 90: matches"),
        "{out}"
    );
    // Three regions, largest first (ties from the top), each told at its middle pixel.
    assert!(out.contains("3 regions of off pixels"), "{out}");
    let listed: Vec<&str> = out
        .lines()
        .filter(|l| l.starts_with("  1. ") || l.starts_with("  2. ") || l.starts_with("  3. "))
        .collect();
    assert_eq!(listed.len(), 2, "{out}");
    assert!(
        listed[0].starts_with("  1. 3 pixels in (10, 5)–(12, 5); at (11, 5):"),
        "{out}"
    );
    assert!(
        listed[1].starts_with("  2. 3 pixels in (30, 20)–(32, 20); at (31, 20):"),
        "{out}"
    );
    assert!(out.contains("… and 1 smaller region"), "{out}");
    // (36, 21) is on the red sheared sphere, centred at world x = 1.2 = (36.5/50 − ½)·5: its
    // story says so, with t, the normal rule and the bytes each image should hold.
    let o = diff(&dir, "mine.png", &line, &[]);
    let out = String::from_utf8_lossy(&o.stdout);
    let third = out
        .split("  3. ")
        .nth(1)
        .unwrap_or_else(|| panic!("no third region:\n{out}"));
    assert!(
        third.starts_with("1 pixel in (36, 21)–(36, 21); at (36, 21):")
            && third.contains("Sphere")
            && third.contains("t = ")
            && third.contains("normal by (M⁻¹)ᵀ")
            && third.contains("each image there: colour ["),
        "{third}"
    );
    let map = image::open(dir.join("mine.diff.png"))
        .expect("heat map")
        .to_rgb8();
    for (x, row, p) in map.enumerate_pixels() {
        let marked = spots.iter().any(|s| (s.0, s.1) == (x, row));
        assert_eq!(
            p[0] == 255 && p[2] == 0 && p[1] >= 9,
            marked,
            "({x}, {row}) {:?}",
            p.0
        );
    }
    // A stricter grader fails it.
    assert_eq!(
        diff(&dir, "mine.png", &line, &["--min-match", "99.9"])
            .status
            .code(),
        Some(3)
    );
}

#[test]
fn diff_of_a_wrong_image_or_a_wrong_size_does_not_match() {
    let dir = temp_dir("diff-wrong");
    let scene = repo().join("scenes/sheared_sphere.txt");
    let line = course_line(&scene);
    let args: Vec<&str> = line.iter().map(String::as_str).collect();
    assert!(tracelab(&args, &dir).status.success());
    // The incorrect normal rule: the classic wrong images, colour and normals.
    let s = scene.to_str().expect("utf-8");
    let o = tracelab(
        &[
            "-input",
            s,
            "-size",
            "50",
            "40",
            "-output",
            "wrong.png",
            "-normals",
            "n.png",
            "-depth",
            "8",
            "11",
            "d.png",
            "-normal_transform",
            "incorrect",
        ],
        &dir,
    );
    assert!(o.status.success());
    let o = diff(&dir, "wrong.png", &line, &[]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(3), "{out}");
    assert!(
        out.contains("colour wrong.png:") && out.contains("does not match"),
        "{out}"
    );
    assert!(
        out.starts_with(
            "diagnosis: your images match tracelab's render with one known mistake: normals transformed by M instead of (M⁻¹)ᵀ (normal-by-m)\n"
        ),
        "the mistake is named first:\n{out}"
    );
    // Wrong size: said with both sizes, before any pixel.
    let o = tracelab(
        &["-input", s, "-size", "40", "40", "-output", "small.png"],
        &dir,
    );
    assert!(o.status.success());
    let o = diff(&dir, "small.png", &line, &[]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(3), "{out}");
    assert!(
        out.contains("size 40×40, but the command line asks for 50×40: does not match"),
        "{out}"
    );
    // A missing image is an error (1), a bad line a usage error (2).
    assert_eq!(diff(&dir, "absent.png", &line, &[]).status.code(), Some(1));
    let o = tracelab(
        &["diff", "small.png", "--", "-input", s, "-size", "50"],
        &dir,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn diff_accepts_the_courses_own_reference_images() {
    let shared = common::course_dir();
    let dir = temp_dir("diff-course");
    for f in ["scene2_11_squashed_sphere.txt", "scene2_16_t_scale.txt"] {
        std::fs::copy(shared.join("scenes").join(f), dir.join(f)).expect("copy scene");
    }
    for (img, line) in [
        (
            "output2_11.png",
            "-input scene2_11_squashed_sphere.txt -size 200 200 -output x.png",
        ),
        (
            "output2_16.png",
            "-input scene2_16_t_scale.txt -size 200 200 -output x.png",
        ),
    ] {
        std::fs::copy(shared.join("reference").join(img), dir.join(img)).expect("copy reference");
        let line: Vec<String> = line.split(' ').map(String::from).collect();
        let o = diff(&dir, img, &line, &[]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{img}: {}{}",
            String::from_utf8_lossy(&o.stdout),
            stderr(&o)
        );
    }
    // The depth image of scene2_16 as the bug draws it fails against the reference.
    std::fs::copy(
        shared.join("reference/depth2_16.png"),
        dir.join("depth2_16.png"),
    )
    .expect("copy");
    let line = "-input scene2_16_t_scale.txt -size 200 200 -output bug.png -depth 2 7 bug_depth.png -object_rays normalized-no-rescale";
    let args: Vec<&str> = line.split(' ').collect();
    assert!(tracelab(&args, &dir).status.success());
    let good: Vec<String> =
        "-input scene2_16_t_scale.txt -size 200 200 -output x.png -depth 2 7 bug_depth.png"
            .split(' ')
            .map(String::from)
            .collect();
    let o = diff(&dir, "output2_16.png", &good, &[]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(3), "{out}");
    assert!(
        out.contains("colour output2_16.png: 0 of 40,000 pixels off"),
        "{out}"
    );
    // The depth alone is wrong, and named for it.
    assert!(
        out.starts_with("diagnosis: your images match tracelab's render with one known mistake: the object-space ray direction normalised, but t not rescaled to world space (depth-not-rescaled)"),
        "{out}"
    );
    assert!(
        out.contains("depth bug_depth.png:") && out.contains("does not match"),
        "{out}"
    );
}
