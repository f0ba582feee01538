//! The window's panels and their sizes. Side panels have maximum widths that keep the render
//! view at least [`MIN_VIEW_WIDTH`] wide at any window size (a random drag once grew the
//! tree to 1000 px and the view to nothing, and the width was remembered). egui clamps a
//! remembered size to the range given each frame, so a width remembered from a wider screen
//! is clamped on load too. View › Reset layout gives the panels fresh ids, so egui forgets
//! their sizes and uses the defaults.

pub const MIN_VIEW_WIDTH: f32 = 320.0;
pub const MIN_VIEW_HEIGHT: f32 = 200.0;
pub const TREE_WIDTH: f32 = 280.0;
pub const INSPECTOR_WIDTH: f32 = 300.0;
pub const DOCK_HEIGHT: f32 = 260.0;
/// The smallest window (points): both side panels at their first widths and the view at
/// least `MIN_VIEW_WIDTH` beside them, so no panel is squeezed (at 640 wide the tree's
/// buttons wrapped letter by letter, and egui kept the squeezed width after the window grew).
pub const MIN_WINDOW: [f32; 2] = [960.0, 600.0];
// Checked when compiling: room for the panels' frames and resize handles (about 8 points
// each), and for the menu, view bar and status bar above and below the dock.
const _: () = assert!(TREE_WIDTH + INSPECTOR_WIDTH + MIN_VIEW_WIDTH + 32.0 <= MIN_WINDOW[0]);
const _: () = assert!(DOCK_HEIGHT + MIN_VIEW_HEIGHT + 100.0 <= MIN_WINDOW[1]);
/// egui's own minimum for a side panel.
const MIN_PANEL: f32 = 96.0;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Layout {
    /// Bumped by Reset layout (persisted, so a reset stays reset).
    pub epoch: u64,
    /// Outer widths the side panels had last frame (0: not shown yet), so each panel's limit
    /// can leave room for the other one and the view.
    tree: f32,
    inspector: f32,
}

impl Layout {
    /// The panel id: the plain name at first, so sizes remembered by earlier versions are
    /// found (and clamped); a new name after each reset.
    fn id(&self, name: &str) -> String {
        if self.epoch == 0 {
            name.to_string()
        } else {
            format!("{name}#{}", self.epoch)
        }
    }

    /// The id of a panel nested in one of these (the Ray panel in the dock).
    pub fn panel_id(&self, name: &str) -> String {
        self.id(name)
    }

    /// The scene tree, left, in a window `total` points wide.
    pub fn tree_panel(&self, total: f32) -> egui::Panel {
        let inspector = if self.inspector > 0.0 {
            self.inspector
        } else {
            INSPECTOR_WIDTH
        };
        egui::Panel::left(self.id("tree"))
            .resizable(true)
            .default_size(TREE_WIDTH)
            .max_size((total - inspector - MIN_VIEW_WIDTH).max(MIN_PANEL))
    }

    /// The inspector, right, in the `left` points the tree leaves.
    pub fn inspector_panel(&self, left: f32) -> egui::Panel {
        egui::Panel::right(self.id("inspector"))
            .resizable(true)
            .default_size(INSPECTOR_WIDTH)
            .max_size((left - MIN_VIEW_WIDTH).max(MIN_PANEL))
    }

    /// The docked pixel inspector, under the render view, in `height` points.
    pub fn dock_panel(&self, height: f32) -> egui::Panel {
        egui::Panel::bottom(self.id("pixel-inspector"))
            .resizable(true)
            .default_size(DOCK_HEIGHT)
            .max_size((height - MIN_VIEW_HEIGHT).max(40.0))
    }

    pub fn shown_tree(&mut self, width: f32) {
        self.tree = width;
    }

    pub fn shown_inspector(&mut self, width: f32) {
        self.inspector = width;
    }

    /// View › Reset layout.
    pub fn reset(&mut self) {
        *self = Layout {
            epoch: self.epoch + 1,
            ..Layout::default()
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reset_names_the_panels_anew() {
        let mut l = Layout::default();
        assert_eq!(l.id("tree"), "tree");
        l.shown_tree(900.0);
        l.reset();
        assert_eq!(l.id("tree"), "tree#1");
        assert_eq!(
            l,
            Layout {
                epoch: 1,
                ..Layout::default()
            }
        );
    }
}
