//! The argument lists: one generator per command, from a repeatable per-case random stream.
//! Every argument carries what it names (input, output, …), so the checks know which files
//! may change.
//!
//! Sizes and counts that a correct program accepts are kept small (sides ≤ 64, frames ≤ 3,
//! repeats and orbit steps ≤ 3), so that a case takes milliseconds in a debug build; values at
//! and beyond the caps are either refused before any work starts (16385, 0, 2³², 10¹², …) or
//! stay cheap (16384×4). 8192×8192, within the documented limits, goes only to `inspect`
//! (one pixel) and to the low-memory cases, where it must end in a message. `animate
//! --frames 10000` (the cap) takes minutes in a debug build and is left to animate's tests.

use std::ffi::{OsStr, OsString};
use std::os::unix::ffi::OsStringExt;
use std::path::PathBuf;

pub const SEED: u64 = 0xc11_f022_5eed_0025;

/// xorshift64 seeded by splitmix64 of (seed, case), as the scene fuzzer's: any case can be
/// replayed alone.
pub struct Rng(u64);

impl Rng {
    pub fn for_case(seed: u64, k: u64) -> Rng {
        let mut z = seed ^ k.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        Rng((z ^ (z >> 31)) | 1)
    }
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    pub fn one_in(&mut self, n: usize) -> bool {
        self.below(n) == 0
    }
    /// One of the `|`-separated words of `list` (`||` holds an empty one).
    fn word<'a>(&mut self, list: &'a str) -> &'a str {
        let n = list.split('|').count();
        list.split('|').nth(self.below(n)).unwrap_or_default()
    }
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Role {
    Plain,
    Input,
    /// Written as asked, through a symlink as `write_atomic` does.
    Output,
    /// `diff`'s images: inputs, with a heat map `STEM.diff…` beside each.
    DiffImage,
    /// `animate --out`: the frames `STEM…` go in this folder.
    AnimateOut,
    Stem,
}

#[derive(Clone, Debug)]
pub struct Arg {
    pub text: OsString,
    pub role: Role,
    /// The path the argument names, when it is not the whole text (`--output=F`).
    pub path: Option<OsString>,
}

impl Arg {
    pub fn path(&self) -> &OsStr {
        self.path.as_deref().unwrap_or(&self.text)
    }
}

fn plain(s: impl Into<OsString>) -> Arg {
    named(s, Role::Plain)
}

fn named(s: impl Into<OsString>, role: Role) -> Arg {
    Arg {
        text: s.into(),
        role,
        path: None,
    }
}

/// A flag with its values, moved, dropped or repeated as one.
#[derive(Clone, Debug)]
struct Group {
    args: Vec<Arg>,
    /// Never dropped or doubled: the size, frames and repeats that keep a correct program
    /// fast (the defaults, 400² to 800², take seconds in a debug build).
    keep: bool,
}

fn group(args: Vec<Arg>) -> Group {
    Group { args, keep: false }
}

fn kept(args: Vec<Arg>) -> Group {
    Group { args, keep: true }
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum StdoutKind {
    File,
    /// `exec >&-`. Rust's runtime reopens a closed descriptor 0-2 on /dev/null, so this is
    /// indistinguishable from `>/dev/null`: only the crash invariants apply.
    Closed,
    /// A pipe whose reader is gone before the first write (`| head -c0`).
    BrokenPipe,
    /// A private full device (mknod c 1 7), as root: every write fails with ENOSPC.
    Full,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug, PartialOrd, Ord)]
pub enum Family {
    Render,
    Course,
    Fmt,
    Inspect,
    Diff,
    Animate,
    Bench,
    BenchProgressive,
    Help,
    Unknown,
}

pub struct Case {
    pub family: Family,
    pub args: Vec<Arg>,
    pub stdout: StdoutKind,
    pub low_memory: bool,
    /// Which optional plants the working folder gets (see `folders::build`).
    pub plants: u64,
    /// The command reads the scene's OBJ files: they are inputs too.
    pub loads_meshes: bool,
    /// Success means a result was printed on standard output.
    pub prints: bool,
}

/// What a case's generator needs besides its random stream.
pub struct Ctx {
    /// Absolute paths in a case stay inside this folder, so a wrong write cannot escape.
    pub case_dir: PathBuf,
    /// Private device nodes can be made: a full standard output is possible.
    pub nodes: bool,
    pub low_memory: bool,
    /// Per mille: how often a value is taken from the hostile lists rather than the
    /// working ones. A case with few hostile values gets past the checks to the work.
    pub hostility: usize,
    /// Or exactly one hostile choice, the N-th: one fault at a time reaches furthest.
    pub single: Option<usize>,
    pub choices: std::cell::Cell<usize>,
}

impl Ctx {
    fn hostile(&self, rng: &mut Rng) -> bool {
        let n = self.choices.get();
        self.choices.set(n + 1);
        self.single == Some(n) || rng.below(1000) < self.hostility
    }
    /// A working value or, as often as the case is hostile, a hostile one.
    fn pick<'a>(&self, rng: &mut Rng, good: &'a str, bad: &'a str) -> &'a str {
        if self.hostile(rng) {
            rng.word(bad)
        } else {
            rng.word(good)
        }
    }
    fn abs(&self, rel: &str) -> OsString {
        self.case_dir.join(rel).into_os_string()
    }
}

const SIZE_OK: &str = "1|2|3|4|5|8|8|8|16|32|64|+8";
const SIZE_BAD: &str = "0|-0|16385|65536|4294967295|4294967296|18446744073709551615|\
    18446744073709551616|99999999999999999999999|-1|-16384|1e308|1e3|8.0|8.5|NaN|nan|inf|-inf|\
    | 8|8 |0x10|١٦";
const FLOAT_OK: &str = "0|1|-1|2|10|90|0.5|-0|1e-45|-2.5";
const FLOAT_BAD: &str = "1e-320|3e38|-3e38|3.4028235e38|-3.4028235e38|3.5e38|1e39|-1e39|1e308|\
    -1e308|1e309|NaN|-nan|inf|-inf|infinity||1,5|0x1p3|1e|--1|1.0.0";
const COUNT_OK: &str = "0|1|2|3";
/// Counts no cap can allow (`--repeat`, `--orbit`), and ones that are not numbers.
const COUNT_BAD: &str = "1000000000000|4294967296|9223372036854775807|18446744073709551615|\
    18446744073709551616|-1|-18446744073709551615|1e3|NaN||3.0";
const THREADS_OK: &str = "0|1|2|3|4";
const THREADS_BAD: &str =
    "100000|1000000000000|4294967296|18446744073709551615|18446744073709551616|-1|NaN|";
const FRAMES_OK: &str = "1|2|3";
const FRAMES_BAD: &str = "0|10001|4294967295|4294967296|18446744073709551616|-1|NaN|";
const INDEX_BAD: &str = "15|16|4294967295|4294967296|18446744073709551615|18446744073709551616|-1|";

fn size_pair(rng: &mut Rng, ctx: &Ctx, one_pixel: bool) -> [String; 2] {
    let ok = |rng: &mut Rng| rng.word(SIZE_OK).to_string();
    let mut pair = if !ctx.hostile(rng) {
        [ok(rng), ok(rng)]
    } else {
        match rng.below(6) {
            0 => [rng.word(SIZE_BAD).into(), ok(rng)],
            1 => [rng.word(SIZE_BAD).into(), rng.word(SIZE_BAD).into()],
            // At the side cap, with a small other side: valid and cheap.
            2 => ["16384".into(), rng.word("1|2|4").into()],
            // Beyond the pixel cap: refused before any work.
            3 | 4 => [
                rng.word("16384|16385|8193|65536").into(),
                rng.word("16384|8193|16385").into(),
            ],
            _ if one_pixel || ctx.low_memory => ["8192".into(), "8192".into()],
            _ => ["8192".into(), "8193".into()],
        }
    };
    if rng.one_in(2) {
        pair.swap(0, 1);
    }
    pair
}

fn long_name(ext: &str) -> OsString {
    OsString::from(format!("{}{ext}", "n".repeat(300)))
}

fn scene_path(rng: &mut Rng, ctx: &Ctx) -> OsString {
    if !ctx.hostile(rng) {
        return rng
            .word("scene.txt|hier.txt|mesh.txt|csg.txt|ctl.txt")
            .into();
    }
    match rng.below(40) {
        0 => OsString::from_vec(b"sc\xe9ne.txt".to_vec()),
        1 => "ctl\u{1b}[2J\u{7}.txt".into(),
        2 => ctx.abs("work/scene.txt"),
        3 => long_name(".txt"),
        _ => rng
            .word(
                "./scene.txt|sub/../scene.txt|sub/scene.txt|link_scene.txt|bad.txt|empty.txt|\
                 bom.txt|bommesh.txt|flat.txt|huge_tri.txt|deep.txt|ctl.txt|fifomesh.txt|\
                 devmesh.txt|missingmesh.txt|pipe.txt|zero_dev|null_dev|sub|sub/|scene.txt/|\
                 missing.txt|dangling.txt|loop_a||-|/|../outside/scene.txt|\
                 to_outside_dir/scene.txt|cube.obj|mine.png|-o.txt|.|..|scene.png|scene.png",
            )
            .into(),
    }
}

fn image_out_path(rng: &mut Rng, ctx: &Ctx) -> OsString {
    if !ctx.hostile(rng) {
        return rng
            .word("out.png|out.ppm|out.tga|old.png|sub/out.bmp")
            .into();
    }
    match rng.below(40) {
        0 => OsString::from_vec(b"out\xff.png".to_vec()),
        1 => ctx.abs("work/abs.png"),
        2 => long_name(".png"),
        3 => "new\nline.png".into(),
        _ => rng
            .word(
                "out.bmp|OUT.PNG|out.jpg|out|.png|link_old.png|dangling.png|dangling_out.png|\
                 loop_a|to_outside.png|abs_outside.png|to_outside_dir/new.png|\
                 ../outside/new.png|../outside/target.png|../escaped.png|sub|sub/|out.png/|\
                 newdir/out.png|a/b/../../out.png|pipe.png|null.png|full.png|scene.txt|\
                 mesh.txt|cube.obj|mine.png|mine.diff.png|frame_0000.png||.|..|-o.png|scene.png",
            )
            .into(),
    }
}

fn image_in_path(rng: &mut Rng, ctx: &Ctx) -> OsString {
    if !ctx.hostile(rng) {
        return rng
            .word("mine.png|mine.png|mine_n.png|mine.diff.png")
            .into();
    }
    rng.word(
        "mine.ppm|old.png|bomb.png|pipe.png|link_mine.png|to_outside.png|../outside/target.png|\
         scene.txt|missing.png|dangling.png|loop_a|sub|sub/|mine.png/|zero_dev|null_dev|",
    )
    .into()
}

/// The course's flags. For `diff`, every file they name is the student's: an input.
fn course_groups(rng: &mut Rng, ctx: &Ctx, for_diff: bool) -> Vec<Group> {
    let (out_role, img_role) = if for_diff {
        (Role::Input, Role::DiffImage)
    } else {
        (Role::Output, Role::Output)
    };
    let image = |rng: &mut Rng| {
        if for_diff && !rng.one_in(3) {
            image_in_path(rng, ctx)
        } else {
            image_out_path(rng, ctx)
        }
    };
    let mut g = vec![group(vec![
        plain("-input"),
        named(scene_path(rng, ctx), Role::Input),
    ])];
    let [w, h] = if for_diff && !ctx.hostile(rng) {
        ["8".into(), "8".into()]
    } else {
        size_pair(rng, ctx, false)
    };
    g.push(kept(vec![plain("-size"), plain(w), plain(h)]));
    if !rng.one_in(6) {
        g.push(group(vec![plain("-output"), named(image(rng), out_role)]));
    }
    if rng.one_in(3) {
        g.push(group(vec![plain("-normals"), named(image(rng), img_role)]));
    }
    if rng.one_in(3) {
        let (min, max) = (
            ctx.pick(rng, FLOAT_OK, FLOAT_BAD),
            ctx.pick(rng, FLOAT_OK, FLOAT_BAD),
        );
        let f = named(image(rng), img_role);
        g.push(group(vec![plain("-depth"), plain(min), plain(max), f]));
    }
    if rng.one_in(3) {
        g.push(group(vec![plain("-shade_back")]));
    }
    if rng.one_in(4) {
        let v = ctx.pick(rng, "correct|incorrect", "Correct||wrong");
        g.push(group(vec![plain("-normal_transform"), plain(v)]));
    }
    if rng.one_in(4) {
        let v = ctx.pick(
            rng,
            "unnormalized|normalized|normalized-no-rescale",
            "|x|Normalized",
        );
        g.push(group(vec![plain("-object_rays"), plain(v)]));
    }
    // Assignments 3-4: shadows, bounces (capped at 100; rays that would double past the cap
    // refused), weight, the optional fix, and the preview's flags (accepted with a note).
    if rng.one_in(4) {
        g.push(group(vec![plain("-shadows")]));
    }
    if rng.one_in(4) {
        let v = ctx.pick(rng, "0|1|3|5|10", "100|101|-1|4294967296|1e3|two|");
        g.push(group(vec![plain("-bounces"), plain(v)]));
    }
    if rng.one_in(4) {
        let v = ctx.pick(rng, "0|0.01|0.5|1", "nan|inf|-0.5|1e39|-0|x|");
        g.push(group(vec![plain("-weight"), plain(v)]));
    }
    if rng.one_in(8) {
        g.push(group(vec![plain("-specular_fix")]));
    }
    if rng.one_in(8) {
        let preview = rng.word("-gui|-gouraud|-tessellation");
        let mut v = vec![plain(preview)];
        if preview == "-tessellation" {
            v.push(plain(ctx.pick(rng, "10|40", "0|-1|x")));
            v.push(plain(ctx.pick(rng, "5|20", "0|1e9|")));
        }
        g.push(group(v));
    }
    // Assignment 7: a sampler (uniform and jittered need a square count, at most 65,536 a
    // pixel), a filter (0 < R ≤ 64, σ ≤ 32), tracelab's seed (only with random or jittered
    // sampling) and the two pictures, whose files are outputs and whose zoom is capped by the
    // image size.
    if rng.one_in(4) {
        let flag = rng.word("-uniform_samples|-random_samples|-jittered_samples");
        let v = ctx.pick(
            rng,
            "1|4|9|16",
            "0|-1|2|8|65537|65536|4294967296|1e3|nan|x|4.0|",
        );
        g.push(group(vec![plain(flag), plain(v)]));
    }
    if rng.one_in(4) {
        let flag = rng.word("-box_filter|-tent_filter|-gaussian_filter");
        let v = ctx.pick(rng, "0.5|1|1.7|2.3", "0|-0|-1|nan|inf|-inf|1e39|64.5|33|x|");
        g.push(group(vec![plain(flag), plain(v)]));
    }
    if rng.one_in(8) {
        let v = ctx.pick(
            rng,
            "0|1|18446744073709551615",
            "-1|18446744073709551616|1e3|x|",
        );
        g.push(group(vec![plain("-seed"), plain(v)]));
    }
    for flag in ["-render_samples", "-render_filter"] {
        if rng.one_in(8) {
            let zoom = ctx.pick(rng, "1|4|20", "0|-1|100000|4294967296|nan|x|");
            g.push(group(vec![
                plain(flag),
                named(image(rng), out_role),
                plain(zoom),
            ]));
        }
    }
    if ctx.hostile(rng) && rng.one_in(3) {
        let flag = rng.word(
            "-bogus|-size2|-Input|-|--input|-jitter|-output=x.png|-grid|-stats|-visualize_grid|\
             -box_filter",
        );
        g.push(group(vec![plain(flag)]));
    }
    g
}

/// `--flag F`, `--flag=F` or `-f F`, naming an output.
fn output_flag(rng: &mut Rng, long: &str, short: Option<&str>, path: OsString) -> Group {
    match rng.below(4) {
        0 => {
            let mut text = OsString::from(format!("{long}="));
            text.push(&path);
            group(vec![Arg {
                text,
                role: Role::Output,
                path: Some(path),
            }])
        }
        1 if short.is_some() => group(vec![
            plain(short.unwrap_or(long)),
            named(path, Role::Output),
        ]),
        _ => group(vec![plain(long), named(path, Role::Output)]),
    }
}

fn render_groups(rng: &mut Rng, ctx: &Ctx) -> Vec<Group> {
    let mut g = Vec::new();
    if !rng.one_in(6) {
        g.push(group(vec![named(scene_path(rng, ctx), Role::Input)]));
    }
    let [w, h] = size_pair(rng, ctx, false);
    g.push(kept(vec![plain("--size"), plain(w), plain(h)]));
    if !rng.one_in(5) {
        let p = image_out_path(rng, ctx);
        g.push(output_flag(rng, "--output", Some("-o"), p));
    }
    if rng.one_in(3) {
        let p = image_out_path(rng, ctx);
        g.push(output_flag(rng, "--normals", None, p));
    }
    if rng.one_in(3) {
        let (min, max) = (
            ctx.pick(rng, FLOAT_OK, FLOAT_BAD),
            ctx.pick(rng, FLOAT_OK, FLOAT_BAD),
        );
        let f = named(image_out_path(rng, ctx), Role::Output);
        g.push(group(vec![plain("--depth"), plain(min), plain(max), f]));
    }
    if rng.one_in(3) {
        g.push(group(vec![plain("--shade-back")]));
    }
    if rng.one_in(4) {
        let v = ctx.pick(rng, "correct|incorrect", "|x");
        g.push(group(vec![plain("--normal-transform"), plain(v)]));
    }
    if rng.one_in(4) {
        let v = ctx.pick(
            rng,
            "unnormalized|normalized|normalized-no-rescale",
            "x|normalized_no_rescale",
        );
        g.push(group(vec![plain("--object-rays"), plain(v)]));
    }
    // Assignment 7, spelled long.
    if rng.one_in(4) {
        let v = ctx.pick(rng, "1|4|9|16", "0|-1|8|65537|4294967296|nan|x|");
        g.push(group(vec![plain("--samples"), plain(v)]));
        if rng.one_in(2) {
            let k = ctx.pick(rng, "uniform|random|jittered", "Random|x|");
            g.push(group(vec![plain("--sampler"), plain(k)]));
        }
    }
    if rng.one_in(4) {
        let flag = rng.word("--box-filter|--tent-filter|--gaussian-filter");
        let v = ctx.pick(rng, "0.5|1.5|0.6", "0|-1|nan|inf|1e39|65|x|");
        g.push(group(vec![plain(flag), plain(v)]));
    }
    if rng.one_in(8) {
        let v = ctx.pick(rng, "0|7", "-1|18446744073709551616|x|");
        g.push(group(vec![plain("--seed"), plain(v)]));
    }
    for flag in ["--render-samples", "--render-filter"] {
        if rng.one_in(8) {
            let zoom = ctx.pick(rng, "1|4|20", "0|-1|100000|4294967296|x|");
            g.push(group(vec![
                plain(flag),
                named(image_out_path(rng, ctx), Role::Output),
                plain(zoom),
            ]));
        }
    }
    g
}

fn fmt_groups(rng: &mut Rng, ctx: &Ctx) -> Vec<Group> {
    let mut g = vec![group(vec![named(scene_path(rng, ctx), Role::Input)])];
    if !rng.one_in(3) {
        let out: OsString = if !ctx.hostile(rng) {
            rng.word("out.txt|hier.txt|sub/out.txt").into()
        } else {
            match rng.below(3) {
                0 => image_out_path(rng, ctx),
                1 => scene_path(rng, ctx),
                _ => rng
                    .word(
                        "out.txt/|newdir/out.txt|../outside/new.txt|pipe.txt|full_dev|\
                         null_dev|link_scene.txt|to_outside.png|scene.txt",
                    )
                    .into(),
            }
        };
        g.push(output_flag(rng, "--output", Some("-o"), out));
    }
    g
}

fn inspect_groups(rng: &mut Rng, ctx: &Ctx) -> Vec<Group> {
    let mut g = Vec::new();
    if !rng.one_in(6) {
        g.push(group(vec![named(scene_path(rng, ctx), Role::Input)]));
    }
    let [w, h] = size_pair(rng, ctx, true);
    let coord = |rng: &mut Rng, side: &str| -> String {
        let n: i64 = side.trim().trim_start_matches('+').parse().unwrap_or(8);
        if !ctx.hostile(rng) {
            return rng.below(n.clamp(1, 64) as usize).to_string();
        }
        match rng.below(4) {
            0 => (n - 1).to_string(),
            1 => n.to_string(),
            _ => rng.word(SIZE_BAD).to_string(),
        }
    };
    let (x, y) = (coord(rng, &w), coord(rng, &h));
    g.push(kept(vec![plain("--size"), plain(w), plain(h)]));
    if !rng.one_in(12) {
        g.push(group(vec![plain("--pixel"), plain(x), plain(y)]));
    }
    if rng.one_in(2) {
        g.push(group(vec![plain("--json")]));
    }
    if rng.one_in(4) {
        g.push(group(vec![plain("--shade-back")]));
    }
    if rng.one_in(4) {
        let v = ctx.pick(rng, "normalized-no-rescale|normalized", "y");
        g.push(group(vec![plain("--object-rays"), plain(v)]));
    }
    if rng.one_in(4) {
        let v = ctx.pick(rng, "incorrect|correct", "z");
        g.push(group(vec![plain("--normal-transform"), plain(v)]));
    }
    if rng.one_in(4) {
        let min = ctx.pick(rng, FLOAT_OK, FLOAT_BAD);
        let max = ctx.pick(rng, FLOAT_OK, FLOAT_BAD);
        g.push(group(vec![plain("--depth"), plain(min), plain(max)]));
    }
    g
}

/// `diff --batch COMMANDS --images DIR --report F`: the commands file is any input (a scene
/// is a file of junk lines), the folder a working or hostile one; the report is always named
/// (the invented default would land in the working folder).
fn batch_groups(rng: &mut Rng, ctx: &Ctx) -> Vec<Group> {
    let commands = if ctx.hostile(rng) {
        image_in_path(rng, ctx)
    } else {
        scene_path(rng, ctx)
    };
    let images = ctx.pick(
        rng,
        ".|sub",
        "missing|mine.png|pipe.png|loop_a|dangling.png|",
    );
    let mut g = vec![
        group(vec![plain("--batch"), named(commands, Role::Input)]),
        group(vec![plain("--images"), plain(images)]),
        kept(vec![
            plain("--report"),
            named(image_out_path(rng, ctx), Role::Output),
        ]),
    ];
    if rng.one_in(3) {
        let v = ctx.pick(rng, "0|8|255", "256|-1||NaN");
        g.push(group(vec![plain("--tolerance"), plain(v)]));
    }
    if rng.one_in(4) {
        g.push(group(vec![
            plain("--scenes"),
            plain(ctx.pick(rng, ".", "missing|")),
        ]));
    }
    g
}

fn diff_groups(rng: &mut Rng, ctx: &Ctx) -> Vec<Group> {
    let mut g = vec![group(vec![named(image_in_path(rng, ctx), Role::DiffImage)])];
    if rng.one_in(3) {
        let v = ctx.pick(rng, "0|8|255", "256|-1||NaN");
        g.push(group(vec![plain("--tolerance"), plain(v)]));
    }
    if rng.one_in(3) {
        let v = ctx.pick(rng, "0|99|100|-0|50.5", "100.5|-1|NaN|inf|1e308|");
        g.push(group(vec![plain("--min-match"), plain(v)]));
    }
    if rng.one_in(3) {
        let v = ctx.pick(rng, "0|1|5", "18446744073709551615|18446744073709551616|-1");
        let flag = if rng.one_in(2) {
            "--worst"
        } else {
            "--regions"
        };
        g.push(group(vec![plain(flag), plain(v)]));
    }
    g
}

fn animate_groups(rng: &mut Rng, ctx: &Ctx) -> Vec<Group> {
    // hier.txt's Transforms are nodes 4, 6, 9 and 11; mesh.txt's 1 and 3.
    let (scene, nodes) = match rng.below(3) {
        _ if ctx.hostile(rng) => (scene_path(rng, ctx), "0|1|2|3|4|6"),
        0 => ("mesh.txt".into(), "1|3"),
        _ => ("hier.txt".into(), "4|6|9|11"),
    };
    let mut g = vec![group(vec![named(scene, Role::Input)])];
    let [w, h] = if ctx.hostile(rng) {
        size_pair(rng, ctx, false)
    } else {
        [rng.word("1|2|4|8|16").into(), rng.word("1|2|4|8|16").into()]
    };
    g.push(kept(vec![plain("--size"), plain(w), plain(h)]));
    if rng.one_in(3) {
        // A bounce sweep: a few frames at most when it works; ends out of bounds, the wrong
        // way round or missing, a mix with the op sweep's flags, and hostile weights.
        for flag in ["--bounces-from", "--bounces-to"] {
            let v = ctx.pick(rng, "0|1|2|3", "101|-1|4294967296|NaN|1e39|");
            g.push(group(vec![plain(flag), plain(v)]));
        }
        if rng.one_in(3) {
            g.push(group(vec![plain("--shadows")]));
        }
        if rng.one_in(3) {
            g.push(group(vec![plain("--shade-back")]));
        }
        if rng.one_in(3) {
            let v = ctx.pick(rng, "0|0.01|1", "NaN|inf|-1|");
            g.push(group(vec![plain("--weight"), plain(v)]));
        }
        if ctx.hostile(rng) {
            let mix = rng.word("--node|--from|--frames|--op");
            g.push(group(vec![plain(mix), plain("1")]));
        }
    } else {
        // Frames too: the default (24) is cheap at these sizes but not at 16384×4.
        let frames = ctx.pick(rng, FRAMES_OK, FRAMES_BAD);
        g.push(kept(vec![plain("--frames"), plain(frames)]));
        let node = ctx.pick(rng, nodes, INDEX_BAD);
        g.push(group(vec![plain("--node"), plain(node)]));
        if rng.one_in(2) {
            let op = ctx.pick(rng, "0|0|1|2", INDEX_BAD);
            g.push(group(vec![plain("--op"), plain(op)]));
        }
        if rng.one_in(2) {
            let c = ctx.pick(rng, "0|0|1|2|3", INDEX_BAD);
            g.push(group(vec![plain("--component"), plain(c)]));
        }
        for flag in ["--from", "--to"] {
            let v = ctx.pick(rng, FLOAT_OK, FLOAT_BAD);
            g.push(group(vec![plain(flag), plain(v)]));
        }
    }
    if rng.one_in(4) {
        let v = ctx.pick(rng, "0|1|100|65535", "65536|-1|");
        g.push(group(vec![plain("--delay-ms"), plain(v)]));
    }
    if rng.one_in(4) {
        g.push(group(vec![plain("--compare")]));
    }
    if rng.one_in(5) {
        let v = ctx.pick(rng, "incorrect|correct", "x");
        g.push(group(vec![plain("--normal-transform"), plain(v)]));
    }
    if !rng.one_in(3) {
        let out: OsString = if !ctx.hostile(rng) {
            rng.word(".|outdir|outdir/|newdir").into()
        } else {
            match rng.below(12) {
                0 => ctx.abs("work/outdir"),
                1 => image_out_path(rng, ctx),
                _ => rng
                    .word(
                        "new/deeper|to_outside_dir|../outside|..|scene.txt|pipe.txt||\
                         sub/../outdir|missing/",
                    )
                    .into(),
            }
        };
        g.push(group(vec![plain("--out"), named(out, Role::AnimateOut)]));
    }
    if !rng.one_in(3) {
        let stem: OsString = if !ctx.hostile(rng) {
            rng.word("frame|f|mine|scene").into()
        } else {
            // Absolute stems point inside the case's folder, never at the machine's.
            match rng.below(14) {
                0 => ctx.abs("outside/abs_stem"),
                1 => OsString::from_vec(b"st\xffem".to_vec()),
                2 => long_name(""),
                _ => rng
                    .word("|.|..|../x|sub/x|a\nb|-x|frame.apng|x/|to_outside_dir/x")
                    .into(),
            }
        };
        g.push(group(vec![plain("--stem"), named(stem, Role::Stem)]));
    }
    g
}

fn bench_groups(rng: &mut Rng, ctx: &Ctx, progressive: bool) -> Vec<Group> {
    let mut g = vec![group(vec![named(scene_path(rng, ctx), Role::Input)])];
    let [w, h] = size_pair(rng, ctx, false);
    g.push(kept(vec![plain("--size"), plain(w), plain(h)]));
    // Repeats: the defaults (5, 10) are cheap at these sizes; a cap-edge value must be refused.
    let repeat = ctx.pick(rng, COUNT_OK, COUNT_BAD);
    g.push(kept(vec![plain("--repeat"), plain(repeat)]));
    if rng.one_in(2) {
        let t = ctx.pick(rng, THREADS_OK, THREADS_BAD);
        g.push(group(vec![plain("--threads"), plain(t)]));
    }
    if progressive {
        if rng.one_in(3) {
            let steps = ctx.pick(rng, COUNT_OK, COUNT_BAD);
            g.push(group(vec![plain("--orbit"), plain(steps)]));
        }
        if rng.one_in(4) {
            g.push(group(vec![plain("--single-rays")]));
        }
        if rng.one_in(4) {
            g.push(group(vec![plain("--one-pass")]));
        }
    } else if rng.one_in(3) {
        g.push(group(vec![plain("--packets")]));
    }
    g
}

/// Any command's groups, for a flag inserted into another command's line.
fn any_groups(rng: &mut Rng, ctx: &Ctx) -> Vec<Group> {
    match rng.below(7) {
        0 => render_groups(rng, ctx),
        1 => course_groups(rng, ctx, false),
        2 => inspect_groups(rng, ctx),
        3 => diff_groups(rng, ctx),
        4 => animate_groups(rng, ctx),
        5 => fmt_groups(rng, ctx),
        _ => bench_groups(rng, ctx, true),
    }
}

/// Edits that keep each value with its flag, as often as the case is hostile: drop, repeat or
/// swap groups, insert another command's flag, empty a value; and last, cut the last group
/// short (last, so that no value slides under another flag).
fn mutate(groups: &mut Vec<Group>, rng: &mut Rng, ctx: &Ctx) {
    for _ in 0..3 {
        if !ctx.hostile(rng) {
            continue;
        }
        let n = groups.len();
        match rng.below(5) {
            0 if n > 0 => {
                let i = rng.below(n);
                if !groups[i].keep {
                    groups.remove(i);
                }
            }
            1 if n > 0 => {
                let i = rng.below(n);
                if !groups[i].keep {
                    let copy = groups[i].clone();
                    groups.insert(rng.below(n + 1), copy);
                }
            }
            2 if n > 1 => groups.swap(rng.below(n), rng.below(n)),
            3 => {
                let mut junk = any_groups(rng, ctx);
                let one = junk.swap_remove(rng.below(junk.len()));
                // A second size would be one that may be large: only the first one is kept small.
                if !one.keep {
                    groups.insert(rng.below(n + 1), one);
                }
            }
            _ if n > 0 => {
                let i = rng.below(n);
                let m = groups[i].args.len();
                let a = &mut groups[i].args[rng.below(m)];
                a.text = OsString::new();
                a.path = None;
            }
            _ => {}
        }
    }
    if ctx.hostile(rng)
        && rng.one_in(2)
        && let Some(last) = groups.last_mut()
        && last.args.len() > 1
        && !last.keep
    {
        let m = 1 + rng.below(last.args.len() - 1);
        last.args.truncate(m);
    }
}

fn flatten(head: &[&str], groups: Vec<Group>) -> Vec<Arg> {
    head.iter()
        .map(|h| plain(*h))
        .chain(groups.into_iter().flat_map(|g| g.args))
        .collect()
}

pub fn generate(k: u64, ctx: &Ctx) -> Case {
    let mut rng = Rng::for_case(SEED, k);
    let family = match rng.below(20) {
        0..=2 => Family::Render,
        3..=5 => Family::Course,
        6 | 7 => Family::Fmt,
        8 | 9 => Family::Inspect,
        10..=12 => Family::Diff,
        13..=15 => Family::Animate,
        16 => Family::Bench,
        17 => Family::BenchProgressive,
        18 => Family::Help,
        _ => Family::Unknown,
    };
    let (mut prints, mut loads_meshes) = (true, true);
    let line = |head: &[&str], mut g: Vec<Group>, rng: &mut Rng| {
        mutate(&mut g, rng, ctx);
        flatten(head, g)
    };
    let args = match family {
        Family::Render => {
            prints = false;
            let g = render_groups(&mut rng, ctx);
            line(&["render"], g, &mut rng)
        }
        Family::Course => {
            prints = false;
            let g = course_groups(&mut rng, ctx, false);
            line(&[], g, &mut rng)
        }
        Family::Fmt => {
            loads_meshes = false;
            let g = fmt_groups(&mut rng, ctx);
            let args = line(&["fmt"], g, &mut rng);
            // `-o` with its value attached (`-object_rays` is `-o bject_rays`) names an
            // output too (the 1,000,000-case run's case 829517).
            prints = !args.iter().any(|a| {
                a.role == Role::Output
                    || (a.text.as_encoded_bytes().starts_with(b"-o") && a.text.len() > 2)
            });
            args
        }
        Family::Inspect => {
            let g = inspect_groups(&mut rng, ctx);
            line(&["inspect"], g, &mut rng)
        }
        Family::Diff if rng.one_in(4) => {
            // The commands file is no handout's: no line names a scene, so no mesh is read.
            loads_meshes = false;
            let g = batch_groups(&mut rng, ctx);
            line(&["diff"], g, &mut rng)
        }
        Family::Diff => {
            let pre = diff_groups(&mut rng, ctx);
            let course = course_groups(&mut rng, ctx, true);
            let mut args = line(&["diff"], pre, &mut rng);
            // The `--` forgotten (the issue's `unknown option "diff"`).
            if !(ctx.hostile(&mut rng) && rng.one_in(3)) {
                args.push(plain("--"));
            }
            args.extend(line(&[], course, &mut rng));
            args
        }
        Family::Animate => {
            prints = false;
            let g = animate_groups(&mut rng, ctx);
            line(&["animate"], g, &mut rng)
        }
        Family::Bench => {
            let g = bench_groups(&mut rng, ctx, false);
            line(&["bench"], g, &mut rng)
        }
        Family::BenchProgressive => {
            let g = bench_groups(&mut rng, ctx, true);
            line(&["bench-progressive"], g, &mut rng)
        }
        Family::Help => {
            loads_meshes = false;
            let sub = rng.word("render|animate|diff|inspect|fmt|bench|bench-progressive|help");
            let words = match rng.below(9) {
                0 => vec!["--help"],
                1 => vec!["-h"],
                2 => vec!["--version"],
                3 => vec!["-V"],
                4 => vec!["help"],
                5 => vec!["help", sub],
                6 => vec![sub, "--help"],
                7 => vec![sub, "-h"],
                _ => vec!["--help", "render", "--size", "0", "0"],
            };
            words.into_iter().map(plain).collect()
        }
        Family::Unknown => {
            (prints, loads_meshes) = (false, false);
            // Near misses of the subcommands: none is a file, so none may open the editor.
            let word = rng.word(
                "rendr|Render|RENDER|rende|renderr|fmtt|fm|diff2|dif|animat|animates|inspekt|\
                 bench-progresive|benchprogressive|bench_progressive|bnech|hlep|render-|ren der",
            );
            let mut args = vec![plain(word)];
            if rng.one_in(2) {
                let mut g = render_groups(&mut rng, ctx);
                g.retain(|g| !g.args.iter().any(|a| a.role == Role::Input));
                args.extend(g.into_iter().flat_map(|g| g.args));
            }
            args
        }
    };
    let mut args = args;
    // A collision made on purpose: an output (or diff's image) named as one of the inputs.
    if ctx.hostile(&mut rng) && rng.one_in(2) {
        let pick = |args: &[Arg], roles: &[Role], rng: &mut Rng| {
            let at: Vec<usize> = (0..args.len())
                .filter(|&i| roles.contains(&args[i].role) && args[i].path.is_none())
                .collect();
            (!at.is_empty()).then(|| at[rng.below(at.len())])
        };
        let outputs = [Role::Output, Role::DiffImage, Role::AnimateOut];
        if let (Some(i), Some(o)) = (
            pick(&args, &[Role::Input, Role::DiffImage], &mut rng),
            pick(&args, &outputs, &mut rng),
        ) {
            args[o].text = args[i].text.clone();
        }
    }
    let stdout = match rng.below(16) {
        0 | 1 => StdoutKind::Closed,
        2 | 3 => StdoutKind::BrokenPipe,
        4..=6 if ctx.nodes => StdoutKind::Full,
        _ => StdoutKind::File,
    };
    Case {
        family,
        args,
        stdout,
        low_memory: ctx.low_memory,
        plants: rng.next(),
        loads_meshes,
        prints,
    }
}
