//! Every action the UI can ask for, as a value. Panels, menus, shortcuts, dropped files and
//! file dialogs queue them ([`TracelabApp::queue`]); [`TracelabApp::run_commands`] carries
//! them out, once a frame, in one place — as rerun's viewer does with its commands.

use std::path::PathBuf;

use tracelab_core::NodeId;

use crate::animation::AnimationForm;
use crate::document::Selection;
use crate::document::edit::Edit;
use crate::navigation::AxisView;

#[derive(Clone, Debug, PartialEq)]
pub enum AppCommand {
    /// Select something in the scene (or nothing).
    Select(Option<Selection>),
    /// Change the document (recorded for undo).
    Edit(Edit),
    /// Set a TriangleMesh's file and read it from disk (see `Document::load_mesh`).
    LoadMesh {
        node: NodeId,
        obj_file: String,
    },
    /// Delete the selected node (the Delete key).
    DeleteSelected,
    /// Trace one pixel of the image on screen for the pixel inspector, and select what it hit.
    Inspect {
        frame: usize,
        x: u32,
        row: u32,
    },
    New,
    /// Ask for a file to open.
    OpenDialog,
    Open(PathBuf),
    /// Open a figure of the Lecture menu (index into `lecture::FIGURES`) and set its view.
    OpenLecture(usize),
    /// Hide the lecture figure's caption.
    CloseCaption,
    /// Open File › Export animation for the selected Transform.
    AnimationDialog,
    StartAnimation(AnimationForm),
    CancelAnimation,
    CloseAnimationDialog,
    Save,
    /// Ask where to save.
    SaveAsDialog,
    SaveAs(PathBuf),
    /// Ask where to export the view.
    ExportDialog,
    Export(PathBuf),
    /// Read the document's file again.
    Reload,
    Quit,
    Undo,
    Redo,
    ShowPixelInspector(bool),
    /// The Ray panel's diagrams beside the pixel inspector's story.
    ShowRayPanel(bool),
    /// The Ray panel's diagrams in a window of their own (resizable, as big as wanted)
    /// instead of the dock.
    RayDiagramsInWindow(bool),
    /// Shadows, bounces, weight and the specular fix of the view (View › Rays).
    SetRays(tracelab_core::render::Secondary),
    /// Render through the course's uniform grid, or show it (View › Uniform grid).
    SetGrid(crate::gui::grid_view::GridSettings),
    /// The view's sampler and filter (View › Supersampling); `None`: one ray a pixel.
    SetSupersampling(Option<tracelab_core::render::Supersampling>),
    ResetLayout,
    /// Move the camera to show the selected node whole (F).
    FrameSelected,
    /// Move the camera to show the whole scene (Home).
    FrameAll,
    /// Look along an axis, the scene framed (1, 3, 7 as Blender's numpad).
    AxisView(AxisView),
    /// Esc during a drag in the view: back to the state `mark` (see `Document::revert_to`).
    CancelDrag {
        mark: u64,
    },
}

impl AppCommand {
    /// Commands the panels send about what they show: their own widget state stays valid
    /// after them. Any other change to the document gives the panels fresh widget ids.
    pub fn from_panels(&self) -> bool {
        matches!(
            self,
            AppCommand::Select(_) | AppCommand::Edit(_) | AppCommand::LoadMesh { .. }
        )
    }
}

impl From<Edit> for AppCommand {
    fn from(e: Edit) -> Self {
        AppCommand::Edit(e)
    }
}
