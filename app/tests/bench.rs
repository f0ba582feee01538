//! `tracelab bench` and `tracelab bench-progressive` as ../shared/perf/compare.sh and a
//! reader of docs/perf.md use them: the last line's format, and checksums against rays
//! computed here independently, with the camera formula of ../shared/perf/embree_bench.cpp.

use std::path::PathBuf;
use std::process::{Command, Output};

fn tracelab(args: &[&str], dir: &PathBuf) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run tracelab")
}

/// A scene with a 2×2 quad (two triangles, in an OBJ file) at z = 0, seen from z = 5.
fn quad_scene(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tracelab-bench-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    std::fs::write(
        d.join("quad.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n",
    )
    .expect("obj");
    std::fs::write(
        d.join("quad.txt"),
        "PerspectiveCamera { center 0 0 5 direction 0 0 -1 up 0 1 0 angle 60 }\n\
         Lights { numLights 0 }\n\
         Background { color 0 0 0 }\n\
         Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n\
         Group { numObjects 1 MaterialIndex 0 TriangleMesh { obj_file quad.obj } }\n",
    )
    .expect("scene");
    d
}

/// (hits, sum of t) for the quad, pixel centres, full vertical field of view.
fn expected(w: u32, h: u32) -> (u64, f64) {
    let half = (30f64).to_radians().tan();
    let (mut hits, mut sum) = (0, 0.0);
    for j in 0..h {
        for i in 0..w {
            let x = (2.0 * (i as f64 + 0.5) - w as f64) / h as f64 * half;
            let y = (h as f64 - 2.0 * (j as f64 + 0.5)) / h as f64 * half;
            // The ray (x, y, -1) meets z = 0 at 5·(x, y); t is the distance travelled.
            if (5.0 * x).abs() < 1.0 && (5.0 * y).abs() < 1.0 {
                hits += 1;
                sum += 5.0 * (x * x + y * y + 1.0).sqrt();
            }
        }
    }
    (hits, sum)
}

fn field(line: &str, key: &str) -> f64 {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(&format!("{key}=")))
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no {key}= in {line:?}"))
}

#[test]
fn bench_last_line_carries_the_checksums_of_the_embree_rays() {
    let d = quad_scene("checksums");
    // Square, as compare.sh runs it: for other shapes tracelab follows the course (the larger
    // side spans the angle) and Embree's formula the height. 61 is odd and not a multiple of
    // 4: the packet mode's last tiles are partial in both directions.
    for (size, threads, packets) in [
        (64, "1", false),
        (64, "2", false),
        (64, "1", true),
        (61, "2", true),
    ] {
        let (want_hits, want_sum) = expected(size, size);
        assert!(want_hits > 100, "the quad must cover part of the image");
        let size = size.to_string();
        let mut args = vec![
            "bench",
            "quad.txt",
            "--size",
            &size,
            &size,
            "--threads",
            threads,
            "--repeat",
            "2",
        ];
        if packets {
            args.push("--packets");
        }
        let what = format!("{size}x{size}, {threads} threads, packets {packets}");
        let o = tracelab(&args, &d);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let out = String::from_utf8_lossy(&o.stdout);
        let last = out.lines().last().unwrap_or_default();
        assert!(
            last.starts_with("BENCH mrays_per_s="),
            "last line: {last:?}"
        );
        assert_eq!(last.ends_with("mode=packets"), packets, "{what}: {last}");
        assert!(field(last, "mrays_per_s") > 0.0);
        assert!(field(last, "build_ms") >= 0.0);
        assert_eq!(field(last, "hits") as u64, want_hits, "{what}");
        let sum = field(last, "sum_t");
        assert!(
            (sum - want_sum).abs() <= 1e-5 * want_sum,
            "{what}: sum_t {sum} vs {want_sum}"
        );
        assert!(
            out.contains("bytes/triangle"),
            "memory per triangle is printed:\n{out}"
        );
    }
}

#[test]
fn bench_progressive_reports_coarse_before_full() {
    let d = quad_scene("progressive");
    let o = tracelab(
        &[
            "bench-progressive",
            "quad.txt",
            "--size",
            "64",
            "64",
            "--repeat",
            "2",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    let last = out.lines().last().unwrap_or_default();
    assert!(last.starts_with("PROGRESSIVE "), "last line: {last:?}");
    let (coarse, full) = (field(last, "coarse_ms"), field(last, "full_ms"));
    assert!(coarse > 0.0 && coarse <= full, "{last}");
    // Each pass's own time by its scale, the first being the coarse image's; this tiny scene's
    // quick coarse passes go straight to the full one in some runs or all.
    let passes = out
        .lines()
        .find_map(|l| l.strip_prefix("passes: "))
        .expect("a passes line");
    let each: Vec<(&str, f64)> = passes
        .split(" ms each")
        .next()
        .unwrap_or_default()
        .split(" + ")
        .map(|p| {
            let (scale, rest) = p.split_once("× ").expect("scale× time");
            (
                scale,
                rest.split(' ')
                    .next()
                    .and_then(|t| t.parse().ok())
                    .expect("a number"),
            )
        })
        .collect();
    let scales: Vec<&str> = each.iter().map(|e| e.0).collect();
    assert!(
        [
            &["16", "8", "4", "2", "1"][..],
            &["16", "8", "4", "1"],
            &["16", "8", "1"]
        ]
        .contains(&&scales[..]),
        "{passes}"
    );
    assert!(
        each.iter().all(|e| e.1 >= 0.0) && (each[0].1 - coarse).abs() < 0.006,
        "{passes} / {last}"
    );
}

#[test]
fn bench_progressive_times_single_rays_when_asked() {
    let d = quad_scene("progressive-single");
    for (flag, says) in [
        (None, "in packets of 8"),
        (Some("--single-rays"), "one at a time"),
    ] {
        let mut args = vec![
            "bench-progressive",
            "quad.txt",
            "--size",
            "32",
            "32",
            "--repeat",
            "1",
        ];
        args.extend(flag);
        let o = tracelab(&args, &d);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(out.contains(&format!("primary rays {says}")), "{out}");
        assert!(
            out.lines()
                .last()
                .unwrap_or_default()
                .starts_with("PROGRESSIVE "),
            "{out}"
        );
    }
}

#[test]
fn bench_progressive_times_a_camera_orbit_per_step() {
    let d = quad_scene("orbit");
    let o = tracelab(
        &[
            "bench-progressive",
            "quad.txt",
            "--size",
            "64",
            "64",
            "--repeat",
            "1",
            "--orbit",
            "6",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    let last = out.lines().last().unwrap_or_default();
    assert!(last.starts_with("ORBIT steps=6 "), "last line: {last:?}");
    let (first, coarse, full) = (
        field(last, "first_ms"),
        field(last, "coarse_ms"),
        field(last, "full_ms"),
    );
    assert!(
        first > 0.0 && first <= coarse && coarse <= full * 1.5 + 1.0,
        "{last}"
    );
    assert!(field(last, "max_first_ms") >= first);
}

#[test]
fn bench_of_a_missing_scene_fails_with_its_name() {
    let d = quad_scene("missing");
    let o = tracelab(&["bench", "nope.txt"], &d);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nope.txt"));
}

#[test]
fn repeat_threads_and_orbit_beyond_their_caps_are_usage_errors() {
    let d = quad_scene("caps");
    for (cmd, flag, value, cap) in [
        ("bench", "--repeat", "18446744073709551615", "1000000"),
        ("bench", "--repeat", "1000000000000", "1000000"),
        ("bench", "--threads", "100000", "1024"),
        ("bench", "--threads", "-1", "1024"),
        (
            "bench-progressive",
            "--repeat",
            "18446744073709551615",
            "1000000",
        ),
        ("bench-progressive", "--threads", "1025", "1024"),
        ("bench-progressive", "--orbit", "100001", "100000"),
    ] {
        let o = tracelab(&[cmd, "quad.txt", "--size", "4", "4", flag, value], &d);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{cmd} {flag} {value}: {err}");
        assert!(err.contains(cap), "{cmd} {flag} {value}: {err}");
    }
    let o = tracelab(&["bench", "quad.txt", "--size", "4", "4", "--help"], &d);
    let help = String::from_utf8_lossy(&o.stdout);
    assert!(
        help.contains("at most 1024") && help.contains("at most 1000000"),
        "{help}"
    );
}

/// The "median … ms of N" count on bench's frame line.
fn frames_timed(out: &str) -> usize {
    let line = out
        .lines()
        .find(|l| l.starts_with("frame:"))
        .unwrap_or_else(|| panic!("no frame line in {out}"));
    let after = line
        .split(" ms of ")
        .nth(1)
        .expect("\"ms of\" on the frame line");
    after
        .split(',')
        .next()
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or_else(|| panic!("no frame count in {line:?}"))
}

#[test]
fn short_frames_are_timed_for_a_quarter_second_and_long_runs_as_asked() {
    let d = quad_scene("window");
    // A 2x2 image's frames take microseconds: one asked for, many timed (0.25 s of them, at
    // most 10,000), so a stall of the machine cannot make the median.
    let o = tracelab(
        &["bench", "quad.txt", "--size", "2", "2", "--repeat", "1"],
        &d,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    let n = frames_timed(&out);
    assert!(n > 1 && n <= 10_000, "{n} frames timed:\n{out}");
    // More frames asked for than the window needs: exactly those (the control: the count is
    // the frames timed, not a constant).
    let o = tracelab(
        &["bench", "quad.txt", "--size", "2", "2", "--repeat", "12000"],
        &d,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(frames_timed(&String::from_utf8_lossy(&o.stdout)), 12_000);
}
