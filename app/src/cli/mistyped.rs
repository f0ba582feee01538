//! `tracelab rendr`: a lone argument that is no file and looks like a command, not a scene
//! (no folder, no extension), is a usage error naming the nearest command, rather than the
//! editor opening on a file that does not exist. (The message is escaped where it is
//! printed, `cli::report`.)

use std::path::Path;

/// The usage error for `arg`, or `None` when it should open in the editor: it exists (a
/// file called "rendr" opens), or it names a path or has an extension (a scene to create).
pub(super) fn mistyped_command<'a>(
    arg: &Path,
    commands: impl IntoIterator<Item = &'a str>,
) -> Option<String> {
    if arg.symlink_metadata().is_ok() {
        return None;
    }
    let name = arg.to_str()?;
    if name.is_empty() || name.contains(['/', '.']) || name.contains(std::path::MAIN_SEPARATOR) {
        return None;
    }
    let commands: Vec<&str> = commands.into_iter().collect();
    let nearest = commands
        .iter()
        .map(|c| (edit_distance(&name.to_lowercase(), c), *c))
        .min();
    Some(match nearest {
        // One typo in a short name, two in a longer one.
        Some((d, c)) if d <= 1 + name.chars().count() / 5 => {
            format!("\"{name}\" is neither a file nor a command: did you mean `{c}`?")
        }
        _ => format!(
            "\"{name}\" is neither a file nor a command (commands: {})",
            commands.join(", ")
        ),
    })
}

/// Edits (insert, delete, replace, swap two neighbours) from `a` to `b`.
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    // d[i][j]: distance between a[..i] and b[..j].
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut best = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = best;
        }
    }
    d[a.len()][b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    const COMMANDS: [&str; 4] = ["render", "inspect", "fmt", "bench-progressive"];

    fn check(arg: &str) -> Option<String> {
        mistyped_command(Path::new(arg), COMMANDS)
    }

    #[test]
    fn a_near_miss_names_the_command() {
        for (typo, command) in [
            ("rendr", "render"),
            ("redner", "render"),
            ("Render", "render"),
            ("inspcet", "inspect"),
            ("fmtt", "fmt"),
            ("bench-progresive", "bench-progressive"),
        ] {
            let m = check(typo).unwrap_or_default();
            assert!(
                m.contains(&format!("did you mean `{command}`?")),
                "{typo}: {m}"
            );
        }
    }

    #[test]
    fn a_bare_word_far_from_every_command_lists_them() {
        let m = check("zzzqqq").unwrap_or_default();
        assert!(
            m.contains("neither a file nor a command (commands: render, inspect"),
            "{m}"
        );
        assert!(!m.contains("did you mean"), "{m}");
    }

    #[test]
    fn files_paths_and_names_with_an_extension_open_in_the_editor() {
        let d = std::env::temp_dir().join(format!("tracelab-mistyped-{}", std::process::id()));
        std::fs::create_dir_all(&d).expect("temp dir");
        let existing = d.join("rendr");
        std::fs::write(&existing, "").expect("write");
        assert_eq!(mistyped_command(&existing, COMMANDS), None);
        assert_eq!(check("rendr.txt"), None);
        assert_eq!(check("scenes/rendr"), None);
        assert_eq!(check(""), None);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn edit_distance_counts_a_swap_as_one() {
        assert_eq!(edit_distance("render", "render"), 0);
        assert_eq!(edit_distance("rendr", "render"), 1);
        assert_eq!(edit_distance("redner", "render"), 1);
        assert_eq!(edit_distance("", "fmt"), 3);
    }
}
