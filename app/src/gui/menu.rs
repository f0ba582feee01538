//! The menu bar and the keyboard shortcuts, from one table: each entry's label, its keys and
//! the command it queues.

use egui::{Key, KeyboardShortcut, Modifiers};

use crate::gui::command::AppCommand;
use crate::navigation::AxisView;

pub struct Entry {
    pub command: AppCommand,
    pub label: &'static str,
    /// The keys that run it; the first is named in the menu.
    pub keys: &'static [KeyboardShortcut],
    /// How the menu names the first of `keys`.
    pub keys_text: &'static str,
}

const fn keys(modifiers: Modifiers, key: Key) -> KeyboardShortcut {
    KeyboardShortcut::new(modifiers, key)
}

const CMD: Modifiers = Modifiers::COMMAND;
const CMD_SHIFT: Modifiers = Modifiers::COMMAND.plus(Modifiers::SHIFT);

/// Every menu entry and shortcut. `Modifiers::NONE` keys (Delete) count only while no text
/// field has the keyboard.
pub static ENTRIES: &[Entry] = &[
    Entry {
        command: AppCommand::New,
        label: "New",
        keys: &[keys(CMD, Key::N)],
        keys_text: "Ctrl+N",
    },
    Entry {
        command: AppCommand::OpenDialog,
        label: "Open…",
        keys: &[keys(CMD, Key::O)],
        keys_text: "Ctrl+O",
    },
    Entry {
        command: AppCommand::Save,
        label: "Save",
        keys: &[keys(CMD, Key::S)],
        keys_text: "Ctrl+S",
    },
    Entry {
        command: AppCommand::SaveAsDialog,
        label: "Save As…",
        keys: &[keys(CMD_SHIFT, Key::S)],
        keys_text: "Ctrl+Shift+S",
    },
    Entry {
        command: AppCommand::Reload,
        label: "Reload from disk",
        keys: &[],
        keys_text: "",
    },
    Entry {
        command: AppCommand::ExportDialog,
        label: "Export view…",
        keys: &[],
        keys_text: "",
    },
    Entry {
        command: AppCommand::AnimationDialog,
        label: "Export animation…",
        keys: &[],
        keys_text: "",
    },
    Entry {
        command: AppCommand::Quit,
        label: "Quit",
        keys: &[keys(CMD, Key::Q)],
        keys_text: "Ctrl+Q",
    },
    Entry {
        command: AppCommand::Undo,
        label: "Undo",
        keys: &[keys(CMD, Key::Z)],
        keys_text: "Ctrl+Z",
    },
    Entry {
        command: AppCommand::Redo,
        label: "Redo",
        keys: &[keys(CMD_SHIFT, Key::Z), keys(CMD, Key::Y)],
        keys_text: "Ctrl+Shift+Z",
    },
    Entry {
        command: AppCommand::ResetLayout,
        label: "Reset layout",
        keys: &[],
        keys_text: "",
    },
    Entry {
        command: AppCommand::DeleteSelected,
        label: "Delete",
        keys: &[keys(Modifiers::NONE, Key::Delete)],
        keys_text: "Del",
    },
    Entry {
        command: AppCommand::FrameSelected,
        label: "Frame selected",
        keys: &[keys(Modifiers::NONE, Key::F)],
        keys_text: "F",
    },
    Entry {
        command: AppCommand::FrameAll,
        label: "Frame all",
        keys: &[keys(Modifiers::NONE, Key::Home)],
        keys_text: "Home",
    },
    Entry {
        command: AppCommand::AxisView(AxisView::Front),
        label: "Front view",
        keys: &[keys(Modifiers::NONE, Key::Num1)],
        keys_text: "1",
    },
    Entry {
        command: AppCommand::AxisView(AxisView::Right),
        label: "Side view (right)",
        keys: &[keys(Modifiers::NONE, Key::Num3)],
        keys_text: "3",
    },
    Entry {
        command: AppCommand::AxisView(AxisView::Top),
        label: "Top view",
        keys: &[keys(Modifiers::NONE, Key::Num7)],
        keys_text: "7",
    },
];

/// The table's entry for a command.
fn entry(command: &AppCommand) -> Option<&'static Entry> {
    ENTRIES.iter().find(|e| e.command == *command)
}

/// The menu's text for a command: "Save As… (Ctrl+Shift+S)".
pub fn menu_text(command: &AppCommand) -> String {
    match entry(command) {
        Some(e) if e.keys_text.is_empty() => e.label.to_string(),
        Some(e) => format!("{} ({})", e.label, e.keys_text),
        None => format!("{command:?}"),
    }
}

/// A menu button for a command; queues it when clicked.
pub fn button(
    ui: &mut egui::Ui,
    enabled: bool,
    command: AppCommand,
    out: &mut Vec<AppCommand>,
) -> egui::Response {
    let r = ui.add_enabled(enabled, egui::Button::new(menu_text(&command)));
    if r.clicked() {
        out.push(command);
    }
    r
}

/// A dialog that waits for an answer: while one is up, the scene behind it is out of reach.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dialog {
    /// The built-in or the desktop's file dialog (Open, Save As, Export).
    File,
    /// "Unsaved changes" or "Saving loses something".
    Confirm,
}

/// Whether the keys of `command` may act while `dialog` is up. Every entry of the table acts
/// on the document or opens a dialog of its own, so none does: the keys are left to the
/// dialog's own widgets (Delete and Ctrl+Z in its text field). Undo and Redo also wait while
/// a text field has the keyboard, so Ctrl+Z there undoes the typing, not the scene.
pub fn allowed(command: &AppCommand, dialog: Option<Dialog>, typing: bool) -> bool {
    dialog.is_none() && !(typing && matches!(command, AppCommand::Undo | AppCommand::Redo))
}

/// The commands whose keys were pressed this frame, with `dialog` up (see [`allowed`]).
/// Shortcuts with more modifiers are tried first, so Ctrl+Shift+Z does not also count as
/// Ctrl+Z.
pub fn shortcuts(ctx: &egui::Context, dialog: Option<Dialog>) -> Vec<AppCommand> {
    let typing = ctx.egui_wants_keyboard_input();
    let mut all: Vec<(&KeyboardShortcut, &AppCommand)> = ENTRIES
        .iter()
        .flat_map(|e| e.keys.iter().map(move |k| (k, &e.command)))
        .collect();
    all.sort_by_key(|(k, _)| std::cmp::Reverse(modifier_count(k.modifiers)));
    let mut out: Vec<AppCommand> = Vec::new();
    for (k, command) in all {
        if !allowed(command, dialog, typing) {
            continue;
        }
        let pressed = if k.modifiers.is_none() {
            !typing && ctx.input(|i| i.key_pressed(k.logical_key))
        } else {
            ctx.input_mut(|i| i.consume_shortcut(k))
        };
        if pressed && !out.contains(command) {
            out.push(command.clone());
        }
    }
    out
}

fn modifier_count(m: Modifiers) -> u8 {
    u8::from(m.alt) + u8::from(m.ctrl || m.command || m.mac_cmd) + u8::from(m.shift)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shortcut_belongs_to_one_entry_and_the_menu_names_it() {
        let mut seen = Vec::new();
        for e in ENTRIES {
            for k in e.keys {
                assert!(!seen.contains(k), "{} shares a shortcut", e.label);
                seen.push(*k);
            }
            assert_eq!(e.keys.is_empty(), e.keys_text.is_empty(), "{}", e.label);
        }
        assert_eq!(
            menu_text(&AppCommand::SaveAsDialog),
            "Save As… (Ctrl+Shift+S)"
        );
        assert_eq!(menu_text(&AppCommand::Reload), "Reload from disk");
    }

    #[test]
    fn no_shortcut_reaches_the_scene_behind_a_dialog_and_undo_waits_for_typing() {
        for e in ENTRIES {
            assert!(allowed(&e.command, None, false), "{}", e.label);
            for d in [Dialog::File, Dialog::Confirm] {
                assert!(
                    !allowed(&e.command, Some(d), false),
                    "{} over {d:?}",
                    e.label
                );
            }
        }
        assert!(!allowed(&AppCommand::Undo, None, true));
        assert!(!allowed(&AppCommand::Redo, None, true));
        assert!(allowed(&AppCommand::Save, None, true));
    }
}
