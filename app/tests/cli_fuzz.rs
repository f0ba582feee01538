//! The command-line fuzz harness, beside the scene fuzzer (core/tests/fuzz.rs): repeatable
//! generated argument lists for every subcommand (`render`, the course's `-input … -size …`
//! flags, `fmt`, `inspect`, `diff` with a course line after `--`, `animate`, `bench`,
//! `bench-progressive`, `--help`/`--version`, near-miss subcommand names), run against the
//! built binary, each in its own temporary folder: numbers at and beyond every cap, paths that
//! collide with each other and with the inputs, symlinks (to inputs, out of the folder,
//! dangling, loops), folders, trailing slashes, FIFOs, private device nodes (as root), names
//! that are not UTF-8 or hold control bytes, empty strings. Each case draws how hostile it is
//! (from none to most values hostile), so that many get past the checks to the work and the
//! writes. The lists are in `cli_fuzz/generate.rs`, the folders and what may change in them in
//! `cli_fuzz/folders.rs`.
//!
//! Each case runs `tracelab` in its working folder, standard input null, under `ulimit -v`
//! (2 GB; 1 GB for one case in 16), with a time limit, no display (`DISPLAY` and
//! `WAYLAND_DISPLAY` unset, `HOME` and `XDG_RUNTIME_DIR` private), and its standard output a
//! file, closed, a pipe whose reader is gone, or (as root) a private full device. Invariants:
//! - no panic (`panicked at` on stderr), no death by a signal (abort, out of memory, stack
//!   overflow), an exit code of 0, 1, 2 or 3, no hang;
//! - nothing outside the working folder changes (a sibling `outside` folder holding the
//!   targets of planted symlinks, and `HOME`) unless an argument names it as an output;
//! - no input changes: a file the arguments name as an input (the scene, `diff`'s images and
//!   every file its course line names, the OBJ files of a command that loads meshes) is
//!   byte-identical afterwards, whatever else the line also names it as;
//! - a file nobody named as an output does not change, and an implicit name (heat map,
//!   frame) never follows or replaces a symlink or a file named on the command line;
//! - an output named with a trailing slash (a folder) never becomes a file; a clean exit
//!   leaves no temporary file;
//! - no raw control byte (other than newline and tab) on stderr, nor in the text reports of
//!   `inspect` and `diff`;
//! - the editor never starts (no case names a scene for it; with no display it would say
//!   "cannot open the window");
//! - with standard output a full device, a command that prints its result does not exit 0;
//!   nor does one with an output file on a full device.
//!
//! `TRACELAB_CLI_FUZZ_CASES=N` sets the number of cases (default 10,000: 300 to 370 s of CPU
//! for the debug build, about 3 minutes on 2 idle cores); `TRACELAB_CLI_FUZZ_CASE=K` replays case K
//! alone, printing its arguments and keeping its folder; `TRACELAB_CLI_FUZZ_VERBOSE=1` prints
//! every case and how it ended; `TRACELAB_CLI_FUZZ_THREADS` (default 4) sets the workers and
//! `TRACELAB_CLI_FUZZ_TIMEOUT_S` (default 20) the time limit: a case past it runs again, and is
//! a hang when it passes the limit again (killed at three times the limit). A failure prints
//! the case number, the arguments, the exit status and stderr's tail (the first 30 in full);
//! the test fails at the end with the failing cases grouped by invariant and command, then
//! listed (the first 200).
//!
//! The long, on-demand run (docs/hardening.md gives its expected time):
//!
//! ```text
//! TRACELAB_CLI_FUZZ_CASES=1000000 cargo test --release -p tracelab --test cli_fuzz -- --nocapture
//! ```
#![cfg(target_os = "linux")]

#[path = "cli_fuzz/folders.rs"]
mod folders;
#[path = "cli_fuzz/generate.rs"]
mod generate;

use std::collections::{BTreeMap, BTreeSet};
use std::io::{Read, Write};
use std::os::unix::fs::{FileTypeExt, MetadataExt, OpenOptionsExt};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use folders::{Fixture, Machine, fixture_bytes, written_path};
use generate::{Arg, Case, Ctx, Family, Rng, Role, SEED, StdoutKind, generate};

/// `ulimit -v` in KiB: far above what any generated case needs when the program is correct.
const MEMORY_KB: u64 = 2_000_000;
/// The low limit of one case in 16, under which an 8192×8192 frame cannot fit: such a case
/// must end in a message, not an abort.
const LOW_MEMORY_KB: u64 = 1_000_000;
/// `ulimit -f` in 1 KiB blocks: no case may fill the disk.
const FILE_KB: u64 = 1 << 20;
/// `ulimit -t`: a backstop, so that a case orphaned by a killed harness cannot run for ever
/// (the harness itself kills a case long before).
const CPU_S: u64 = 600;
const STDERR_TAIL: usize = 1500;

fn note(msg: &str) {
    let _ = writeln!(std::io::stderr(), "{msg}");
}

fn env_number(name: &str) -> Option<u64> {
    std::env::var(name).ok().and_then(|v| v.trim().parse().ok())
}

/// Feeds a FIFO named as an input (as a shell's `<(…)` would) or drains one named as an
/// output, until told to stop, so that a program that opens it does not wait forever.
fn fifo_helper(path: PathBuf, content: Option<Vec<u8>>, stop: Arc<AtomicBool>) {
    let nonblock = rustix::fs::OFlags::NONBLOCK.bits() as i32;
    match content {
        Some(bytes) => {
            let mut fed = false;
            while !stop.load(Ordering::Relaxed) {
                // Opening for writing without blocking succeeds only while a reader waits.
                if let Ok(mut f) = std::fs::OpenOptions::new()
                    .write(true)
                    .custom_flags(nonblock)
                    .open(&path)
                {
                    // Once: a second open gets end-of-file at once, as from a spent pipe.
                    if !fed {
                        let mut rest = bytes.as_slice();
                        while !rest.is_empty() && !stop.load(Ordering::Relaxed) {
                            match f.write(rest) {
                                Ok(n) => rest = &rest[n..],
                                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                                    std::thread::sleep(Duration::from_millis(1))
                                }
                                Err(_) => break,
                            }
                        }
                        fed = true;
                    }
                }
                std::thread::sleep(Duration::from_millis(2));
            }
        }
        None => {
            let Ok(mut f) = std::fs::OpenOptions::new()
                .read(true)
                .custom_flags(nonblock)
                .open(&path)
            else {
                return;
            };
            let mut buf = vec![0u8; 1 << 16];
            while !stop.load(Ordering::Relaxed) {
                match f.read(&mut buf) {
                    Ok(n) if n > 0 => {}
                    _ => std::thread::sleep(Duration::from_millis(2)),
                }
            }
        }
    }
}

struct Outcome {
    status: String,
    timed_out: bool,
    /// "exit N", "signal", "timeout": for the table of how far the cases got.
    end: String,
    took: Duration,
    stderr: String,
    wrong: Vec<String>,
}

fn bash() -> &'static str {
    ["/bin/bash", "/usr/bin/bash"]
        .into_iter()
        .find(|p| Path::new(p).exists())
        .unwrap_or("bash")
}

fn run_case(
    case: &Case,
    case_dir: &Path,
    fixture: &Fixture,
    machine: Machine,
    timeout: Duration,
) -> Outcome {
    folders::build(case_dir, fixture, case.plants, machine);
    let work = case_dir.join("work");
    let log = case_dir.join("log");
    let before = folders::snapshot(case_dir);
    let allowed = folders::allowed(case, case_dir);

    let closed = if case.stdout == StdoutKind::Closed {
        "exec >&- ; "
    } else {
        ""
    };
    let script = format!(
        "ulimit -v {} -c 0 -f {FILE_KB} -t {CPU_S} || exit 99; {closed}exec \"$@\"",
        memory_kb(case)
    );
    let stderr_file = std::fs::File::create(log.join("stderr")).expect("stderr file");
    let stdout: Stdio = match case.stdout {
        StdoutKind::File | StdoutKind::Closed => std::fs::File::create(log.join("stdout"))
            .expect("stdout file")
            .into(),
        StdoutKind::BrokenPipe => Stdio::piped(),
        StdoutKind::Full => std::fs::OpenOptions::new()
            .write(true)
            .open(log.join("stdout_full"))
            .expect("the private full device")
            .into(),
    };
    let home = case_dir.join("home");
    let mut cmd = Command::new(bash());
    cmd.arg("-c")
        .arg(script)
        .arg("tracelab")
        .arg(env!("CARGO_BIN_EXE_tracelab"))
        .args(case.args.iter().map(|a| &a.text))
        .current_dir(&work)
        .env_clear()
        .env("PATH", "/usr/local/bin:/usr/bin:/bin")
        .env("HOME", &home)
        .env("XDG_RUNTIME_DIR", home.join("run"))
        .env("XDG_CONFIG_HOME", home.join("config"))
        .env("XDG_DATA_HOME", home.join("data"))
        .env("XDG_CACHE_HOME", home.join("cache"))
        .env("LANG", "C.UTF-8")
        // Bounded threads and malloc arenas, so the address-space limit means the same on a
        // machine with many cores.
        .env("RAYON_NUM_THREADS", "2")
        .env("MALLOC_ARENA_MAX", "2")
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr_file);

    // Helpers for the FIFOs the line names: fed when read, drained when written.
    let stop = Arc::new(AtomicBool::new(false));
    let mut helpers = Vec::new();
    let mut seen = BTreeSet::new();
    for arg in &case.args {
        let p = arg.path();
        let Some(key) = written_path(case_dir, &work, p) else {
            continue;
        };
        let full = case_dir.join(&key);
        let is_fifo = std::fs::symlink_metadata(&full).is_ok_and(|m| m.file_type().is_fifo());
        if !is_fifo || !seen.insert(key.clone()) {
            continue;
        }
        let content = match arg.role {
            Role::Output | Role::AnimateOut | Role::Stem | Role::Plain => None,
            Role::DiffImage => Some(fixture_bytes(fixture, "work/mine.png").to_vec()),
            Role::Input => Some(fixture_bytes(fixture, "work/scene.txt").to_vec()),
        };
        // A FIFO named as input and output both: fed (the output policy must refuse it).
        let content = if allowed.inputs.contains(&key) && content.is_none() {
            Some(fixture_bytes(fixture, "work/scene.txt").to_vec())
        } else {
            content
        };
        let stop = stop.clone();
        helpers.push(std::thread::spawn(move || fifo_helper(full, content, stop)));
    }

    let start = Instant::now();
    let mut child = cmd.spawn().expect("spawn bash");
    // The reader of the pipe goes away before the first write.
    drop(child.stdout.take());
    let mut timed_out = false;
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break s,
            Ok(None) if start.elapsed() > timeout => {
                timed_out = true;
                let _ = child.kill();
                break child.wait().expect("wait");
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(
                (start.elapsed().as_millis() as u64 / 10).clamp(1, 20),
            )),
            Err(e) => panic!("wait: {e}"),
        }
    };
    stop.store(true, Ordering::Relaxed);
    for h in helpers {
        let _ = h.join();
    }

    let stderr_bytes = std::fs::read(log.join("stderr")).unwrap_or_default();
    let stderr = String::from_utf8_lossy(&stderr_bytes).into_owned();
    let mut wrong = Vec::new();
    let code = status.code();
    if timed_out {
        wrong.push(format!("hang: killed after {} s", timeout.as_secs()));
    } else if let Some(sig) = status.signal() {
        wrong.push(format!("killed by signal {sig}"));
    } else if !matches!(code, Some(0..=3)) {
        wrong.push(format!("exit code {code:?} (expected 0, 1, 2 or 3)"));
    }
    if stderr.contains("panicked at") {
        let line = stderr
            .lines()
            .find(|l| l.contains("panicked at"))
            .unwrap_or_default();
        let next = stderr
            .lines()
            .skip_while(|l| !l.contains("panicked at"))
            .nth(1)
            .unwrap_or_default();
        wrong.push(format!("panic: {line} {next}"));
    }
    // Control bytes reach a terminal only escaped (a name with ESC in it could rewrite the
    // screen): stderr always, and the text reports of inspect and diff (fmt's standard
    // output is scene text, written as read).
    let stdout_bytes = match case.stdout {
        StdoutKind::File if matches!(case.family, Family::Inspect | Family::Diff) => {
            std::fs::read(log.join("stdout")).unwrap_or_default()
        }
        _ => Vec::new(),
    };
    for (name, bytes) in [
        ("stderr", &stderr_bytes),
        ("standard output", &stdout_bytes),
    ] {
        if let Some(b) = bytes
            .iter()
            .find(|&&b| (b < 0x20 && b != b'\n' && b != b'\t') || b == 0x7f)
        {
            wrong.push(format!("raw control byte 0x{b:02x} on {name}"));
        }
    }
    if stderr.contains("cannot open the window") {
        wrong.push("the editor started".into());
    }
    if allowed.full_output && code == Some(0) {
        wrong.push("an output is a full device (ENOSPC), yet exit 0".into());
    }
    if case.stdout == StdoutKind::Full && case.prints && code == Some(0) && !timed_out {
        wrong.push("standard output full (ENOSPC), yet exit 0".into());
    }
    let after = folders::snapshot(case_dir);
    wrong.extend(folders::judge(
        &before,
        &after,
        &allowed,
        !timed_out && code.is_some(),
    ));
    Outcome {
        status: if timed_out {
            "killed (timeout)".into()
        } else {
            format!("{status}")
        },
        end: match (timed_out, code) {
            (true, _) => "timeout".into(),
            (false, Some(c)) => format!("exit {c}"),
            (false, None) => "signal".into(),
        },
        took: start.elapsed(),
        timed_out,
        stderr,
        wrong,
    }
}

/// Runs a case in a fresh folder; a case past the time limit runs again with three times the
/// limit, so that a loaded machine does not pass for a hang; past the limit on both runs, it
/// is one (a slow one when it ended).
fn run_confirmed(
    case: &Case,
    case_dir: &Path,
    fixture: &Fixture,
    machine: Machine,
    timeout: Duration,
) -> Outcome {
    let fresh = || {
        let _ = std::fs::remove_dir_all(case_dir);
        std::fs::create_dir_all(case_dir).expect("case dir");
    };
    fresh();
    let first = run_case(case, case_dir, fixture, machine, timeout);
    if !first.timed_out {
        return first;
    }
    fresh();
    let mut again = run_case(case, case_dir, fixture, machine, timeout * 3);
    // Past the limit twice: not the machine's load but the case.
    if !again.timed_out && again.took > timeout {
        again.wrong.push(format!(
            "hang: slow, over {} s twice ({:.0} s on the second run)",
            timeout.as_secs(),
            again.took.as_secs_f64()
        ));
    }
    again
}

fn memory_kb(case: &Case) -> u64 {
    if case.low_memory {
        LOW_MEMORY_KB
    } else {
        MEMORY_KB
    }
}

fn tail(s: &str, n: usize) -> &str {
    let mut start = s.len().saturating_sub(n);
    while !s.is_char_boundary(start) {
        start += 1;
    }
    &s[start..]
}

fn show_args(args: &[Arg]) -> String {
    args.iter()
        .map(|a| {
            let t = a.text.to_string_lossy();
            let plain_ok = !t.is_empty()
                && a.text.to_str().is_some()
                && t.bytes()
                    .all(|b| b.is_ascii_graphic() && b != b'"' && b != b'\\' && b != b'\'');
            if plain_ok {
                t.into_owned()
            } else {
                format!("{:?}", a.text)
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The failure kind, for grouping: the text of a finding up to its first colon.
fn kind_of(finding: &str) -> String {
    let k = finding.split(':').next().unwrap_or(finding);
    if k.starts_with("exit code") {
        "exit code".into()
    } else if k.starts_with("raw control byte") {
        "raw control byte".into()
    } else if k.starts_with("killed by signal") {
        k.into()
    } else if k.starts_with("file ") && k.ends_with("removed") {
        "file removed".into()
    } else {
        k.trim().to_string()
    }
}

fn is_root(dir: &Path) -> bool {
    let probe = dir.join("uid-probe");
    std::fs::write(&probe, b"").is_ok() && std::fs::metadata(&probe).is_ok_and(|m| m.uid() == 0)
}

#[test]
fn generated_command_lines_never_crash_hang_or_touch_what_they_must_not() {
    let only = env_number("TRACELAB_CLI_FUZZ_CASE");
    let n = env_number("TRACELAB_CLI_FUZZ_CASES").unwrap_or(10_000);
    let verbose = std::env::var_os("TRACELAB_CLI_FUZZ_VERBOSE").is_some();
    let threads = env_number("TRACELAB_CLI_FUZZ_THREADS").unwrap_or(4).max(1);
    let timeout = Duration::from_secs(env_number("TRACELAB_CLI_FUZZ_TIMEOUT_S").unwrap_or(20));
    let root_dir = std::env::temp_dir().join(format!("tracelab-clifuzz-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root_dir);
    std::fs::create_dir_all(&root_dir).expect("temp dir");
    let root_dir = std::fs::canonicalize(&root_dir).expect("canonical temp dir");
    // Device nodes only as root, and only where mknod works (not in every container).
    let nodes = is_root(&root_dir)
        && match folders::mknod(
            &root_dir.join("node-probe"),
            rustix::fs::FileType::CharacterDevice,
            (1, 3),
        ) {
            Ok(()) => true,
            Err(e) => {
                note(&format!(
                    "NOTE: root, but mknod fails ({e}): no device-node cases"
                ));
                false
            }
        };
    if !is_root(&root_dir) {
        note("NOTE: not root: no device-node cases and no full standard output");
    }
    let machine = Machine { nodes };
    let fixture = Fixture::new();
    let ctx_for = |k: u64| {
        let case_dir = root_dir.join(format!("case-{k}"));
        // Drawn apart from the case's own stream, so the lists stay as they were.
        let mut side = Rng::for_case(SEED ^ 0x10_3e3, k);
        let low_memory = side.one_in(16);
        // Two in ten cases all working values, three in ten one hostile choice, the rest 5%,
        // 20% or 60% of their choices hostile.
        let hostility = [0, 0, 0, 0, 0, 50, 50, 200, 200, 600][side.below(10)];
        let single = (hostility == 0 && side.below(5) >= 2).then(|| side.below(24));
        Ctx {
            case_dir,
            nodes: machine.nodes,
            low_memory,
            hostility,
            single,
            choices: Default::default(),
        }
    };

    if let Some(k) = only {
        let ctx = ctx_for(k);
        let case = generate(k, &ctx);
        note(&format!(
            "case {k} ({:?}, stdout {:?}, ulimit -v {}): tracelab {}",
            case.family,
            case.stdout,
            memory_kb(&case),
            show_args(&case.args)
        ));
        let o = run_confirmed(&case, &ctx.case_dir, &fixture, machine, timeout);
        note(&format!(
            "status: {}\nstderr (tail):\n{}\nfolder kept: {}",
            o.status,
            tail(&o.stderr, STDERR_TAIL),
            ctx.case_dir.display()
        ));
        assert!(o.wrong.is_empty(), "case {k}:\n  {}", o.wrong.join("\n  "));
        return;
    }

    let next = AtomicU64::new(0);
    // How each command's cases ended, and the slowest cases (for the time limit).
    let ends: Mutex<BTreeMap<(Family, String), u64>> = Mutex::new(BTreeMap::new());
    let slowest: Mutex<Vec<(Duration, u64)>> = Mutex::new(Vec::new());
    let failures: Mutex<Vec<(u64, Family, Vec<String>)>> = Mutex::new(Vec::new());
    let start = Instant::now();
    let (done, shown) = (AtomicU64::new(0), AtomicU64::new(0));
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= n {
                        break;
                    }
                    let ctx = ctx_for(k);
                    let case = generate(k, &ctx);
                    let o = run_confirmed(&case, &ctx.case_dir, &fixture, machine, timeout);
                    let _ = std::fs::remove_dir_all(&ctx.case_dir);
                    if verbose {
                        let first = o.stderr.lines().next().unwrap_or_default();
                        note(&format!(
                            "case {k}: {} [{}] tracelab {}\n    {}",
                            o.end,
                            o.took.as_millis(),
                            show_args(&case.args),
                            tail(first, 200)
                        ));
                    }
                    *ends
                        .lock()
                        .expect("ends")
                        .entry((case.family, o.end.clone()))
                        .or_default() += 1;
                    {
                        let mut slow = slowest.lock().expect("slowest");
                        slow.push((o.took, k));
                        slow.sort_by(|a, b| b.cmp(a));
                        slow.truncate(5);
                    }
                    if !o.wrong.is_empty() {
                        // The details of the first 30; the rest are listed at the end.
                        if shown.fetch_add(1, Ordering::Relaxed) < 30 {
                            note(&format!(
                                "FAIL case {k} ({:?}, stdout {:?}, ulimit -v {}): tracelab {}\n  {}\n  status: {}\n  stderr (tail): {}",
                                case.family,
                                case.stdout,
                                memory_kb(&case),
                                show_args(&case.args),
                                o.wrong.join("\n  "),
                                o.status,
                                tail(&o.stderr, STDERR_TAIL).replace('\n', "\n    ")
                            ));
                        }
                        failures
                            .lock()
                            .expect("failures")
                            .push((k, case.family, o.wrong));
                    }
                    let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                    if d % 1000 == 0 {
                        note(&format!(
                            "cli_fuzz: {d} cases, {:.0} s, {:.1} cases/s",
                            start.elapsed().as_secs_f64(),
                            d as f64 / start.elapsed().as_secs_f64()
                        ));
                    }
                }
            });
        }
    });
    let _ = std::fs::remove_dir_all(&root_dir);
    let secs = start.elapsed().as_secs_f64();
    note(&format!(
        "cli_fuzz: {n} cases in {secs:.1} s ({:.1} cases/s) on {threads} workers",
        n as f64 / secs
    ));
    let mut table = String::from("cli_fuzz: how the cases ended, by command:\n");
    let ends = ends.into_inner().expect("ends");
    let families: BTreeSet<Family> = ends.keys().map(|k| k.0).collect();
    for f in families {
        let row: Vec<String> = ends
            .iter()
            .filter(|(k, _)| k.0 == f)
            .map(|(k, n)| format!("{} ×{n}", k.1))
            .collect();
        table.push_str(&format!("  {f:?}: {}\n", row.join(", ")));
    }
    let slow: Vec<String> = slowest
        .into_inner()
        .expect("slowest")
        .iter()
        .map(|(d, k)| format!("case {k} {:.1} s", d.as_secs_f64()))
        .collect();
    table.push_str(&format!("  slowest: {}", slow.join(", ")));
    note(&table);
    let mut failures = failures.into_inner().expect("failures");
    failures.sort_by_key(|f| f.0);
    if failures.is_empty() {
        return;
    }
    // Grouped by invariant and command, with the first case numbers of each.
    let mut groups: BTreeMap<(String, Family), Vec<u64>> = BTreeMap::new();
    for (k, fam, wrong) in &failures {
        let kinds: BTreeSet<String> = wrong.iter().map(|w| kind_of(w)).collect();
        for kind in kinds {
            groups.entry((kind, *fam)).or_default().push(*k);
        }
    }
    let mut report = format!(
        "{} of {n} cases failed; replay one with TRACELAB_CLI_FUZZ_CASE=K\n",
        failures.len()
    );
    for ((kind, fam), ks) in &groups {
        let first: Vec<String> = ks.iter().take(8).map(u64::to_string).collect();
        report.push_str(&format!(
            "  {kind} [{fam:?}]: {} cases, e.g. {}\n",
            ks.len(),
            first.join(" ")
        ));
    }
    for (k, fam, wrong) in failures.iter().take(200) {
        report.push_str(&format!("case {k} ({fam:?}): {}\n", wrong.join("; ")));
    }
    if failures.len() > 200 {
        report.push_str(&format!("… and {} more\n", failures.len() - 200));
    }
    panic!("{report}");
}
