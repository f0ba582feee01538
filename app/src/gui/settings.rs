//! What the editor keeps between runs, as one struct saved through eframe's storage. Runtime
//! handles (the document, the worker, open dialogs) are not here.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::gui::panels::viewport::{Tab, ViewSettings};

/// eframe's storage key for [`Settings`].
const KEY: &str = "settings";

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    /// Recently opened or saved files, newest first.
    pub recent: Vec<PathBuf>,
    pub tab: Tab,
    pub shade_back: bool,
    /// The depth view's near and far distances.
    pub depth: (f32, f32),
    /// Bumped by View › Reset layout, so the panels forget their dragged sizes.
    pub layout_epoch: u64,
}

impl Default for Settings {
    fn default() -> Self {
        let view = ViewSettings::default();
        Settings {
            recent: Vec::new(),
            tab: view.tab,
            shade_back: view.shade_back,
            depth: view.depth,
            layout_epoch: 0,
        }
    }
}

impl Settings {
    /// The settings saved last, or those a tracelab before this struct saved as strings.
    pub fn load(storage: &dyn eframe::Storage) -> Option<Settings> {
        eframe::get_value(storage, KEY).or_else(|| legacy(storage))
    }

    pub fn save(&self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, KEY, self);
    }
}

/// The keys `recent`, `view` and `layout` of earlier versions, read once so that an upgrade
/// keeps the recent files and the view; the next save writes [`KEY`] instead.
fn legacy(s: &dyn eframe::Storage) -> Option<Settings> {
    let (recent, view, layout) = (
        s.get_string("recent"),
        s.get_string("view"),
        s.get_string("layout"),
    );
    if recent.is_none() && view.is_none() && layout.is_none() {
        return None;
    }
    let mut out = Settings::default();
    if let Some(r) = recent {
        out.recent = r
            .lines()
            .filter(|l| !l.is_empty())
            .map(PathBuf::from)
            .collect();
    }
    if let Some(v) = view {
        let mut it = v.split(' ');
        let mut next = || it.next().unwrap_or("");
        out.tab = match next() {
            "normals" => Tab::Normals,
            "depth" => Tab::Depth,
            "all" => Tab::All,
            _ => Tab::Color,
        };
        out.shade_back = next() == "1";
        if let (Ok(a), Ok(b)) = (next().parse::<f32>(), next().parse::<f32>()) {
            out.depth = (a, b);
        }
    }
    if let Some(e) = layout.and_then(|l| l.trim().parse().ok()) {
        out.layout_epoch = e;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Default)]
    struct Mem(std::collections::HashMap<String, String>);

    impl eframe::Storage for Mem {
        fn get_string(&self, key: &str) -> Option<String> {
            self.0.get(key).cloned()
        }
        fn set_string(&mut self, key: &str, value: String) {
            self.0.insert(key.into(), value);
        }
        fn remove_string(&mut self, key: &str) {
            self.0.remove(key);
        }
        fn flush(&mut self) {}
    }

    #[test]
    fn settings_read_back_as_saved() {
        let s = Settings {
            recent: vec!["a b/c.txt".into()],
            tab: Tab::All,
            shade_back: true,
            depth: (-1.5, 3.0),
            layout_epoch: 2,
        };
        let mut m = Mem::default();
        s.save(&mut m);
        assert_eq!(Settings::load(&m), Some(s));
    }

    #[test]
    fn settings_saved_by_an_earlier_version_as_strings_are_kept() {
        let mut m = Mem::default();
        eframe::Storage::set_string(&mut m, "recent", "/x/one.txt\n/y/two.txt".into());
        eframe::Storage::set_string(&mut m, "view", "depth 1 3 12.5".into());
        eframe::Storage::set_string(&mut m, "layout", "4".into());
        let s = Settings::load(&m).expect("read");
        assert_eq!(
            s.recent,
            [PathBuf::from("/x/one.txt"), PathBuf::from("/y/two.txt")]
        );
        assert_eq!(
            (s.tab, s.shade_back, s.depth, s.layout_epoch),
            (Tab::Depth, true, (3.0, 12.5), 4)
        );
    }
}
