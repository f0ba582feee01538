//! The document as plain data: the scene, where it came from, what is selected, and the
//! undo history. No GUI types here, so all of it is testable without a window.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use tracelab_core::{MeshCache, MeshSlot, NodeId, NodeKind, Problem, Scene, check_scene};

pub mod edit;
mod error;
pub mod notice;
pub mod op_target;

pub use error::{Misfit, OpenError, SaveError};

use crate::io::{Opened, SceneRead, read_scene_file};
use edit::{After, CoalesceKey, Edit, Refusal, apply_checked};
use notice::{Level, Notices};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Selection {
    Camera,
    Lights,
    Light(usize),
    Background,
    Materials,
    Material(usize),
    Node(NodeId),
}

/// Reads `obj_file` (relative to `base`) into `cache` afresh: the file may have changed. Any
/// thread; the error is kept on the node.
pub fn read_mesh(obj_file: &str, base: Option<&Path>, cache: &mut MeshCache) -> MeshSlot {
    match tracelab_core::format::obj::resolve_obj_path(obj_file, base) {
        Ok(p) => {
            cache.forget(&p);
            match cache.load(&p) {
                Ok(m) => MeshSlot::Loaded(m),
                Err(e) => MeshSlot::Failed(format!("{}: {e}", p.display())),
            }
        }
        Err(e) => MeshSlot::Failed(e.to_string()),
    }
}

/// One state in the history: the scene and the id of that state (for the dirty flag).
struct Snapshot {
    scene: Scene,
    state_id: u64,
}

pub struct Document {
    pub scene: Scene,
    /// `None` for the built-in scene or a scene never saved.
    pub path: Option<PathBuf>,
    pub selection: Option<Selection>,
    /// Bumped on every change to `scene`; the render worker drops work for older ones.
    pub generation: u64,
    /// Errors and warnings from the last open, save or edit (file:line:col for scene files).
    pub messages: Notices,
    /// Modification time of `path` when last read or written, to notice outside changes.
    pub disk_stamp: Option<SystemTime>,
    pub mesh_cache: MeshCache,
    /// Comments of the opened file that saving drops (file:line:col: why), for
    /// [`Document::save_warnings`].
    pub lost_comments: Vec<String>,
    undo: Vec<Snapshot>,
    redo: Vec<Snapshot>,
    state_id: u64,
    next_state_id: u64,
    saved_state_id: u64,
    /// The key of the last edit while a drag goes on, so the drag is one undo step.
    gesture: Option<CoalesceKey>,
    /// The scene's broken rules ([`check_scene`]), kept current: edits may leave only
    /// incomplete ones, which block saving.
    problems: Vec<Problem>,
    /// The last edit refused, for the inspector to show beside its field; cleared by the
    /// next change.
    pub refusal: Option<Refusal>,
}

/// Keeps memory bounded on large scenes; 200 steps is far more than anyone undoes.
const MAX_UNDO: usize = 200;

impl Document {
    pub fn new(scene: Scene, path: Option<PathBuf>) -> Self {
        let disk_stamp = path.as_deref().and_then(modified);
        let problems = check_scene(&scene);
        Document {
            problems,
            refusal: None,
            scene,
            path,
            selection: None,
            generation: 1,
            messages: Notices::default(),
            disk_stamp,
            mesh_cache: MeshCache::new(),
            lost_comments: Vec::new(),
            undo: Vec::new(),
            redo: Vec::new(),
            state_id: 0,
            next_state_id: 1,
            saved_state_id: 0,
            gesture: None,
        }
    }

    /// The built-in scene.
    pub fn builtin() -> Self {
        let mut cache = MeshCache::new();
        let out = tracelab_core::parse_scene(
            crate::DEFAULT_SCENE.as_bytes(),
            crate::DEFAULT_SCENE_NAME,
            None,
            &mut cache,
        );
        let scene = out.scene.unwrap_or_default();
        let mut d = Document::new(scene, None);
        d.mesh_cache = cache;
        d
    }

    pub fn title_name(&self) -> String {
        match &self.path {
            Some(p) => p.file_name().map_or_else(
                || p.display().to_string(),
                |n| n.to_string_lossy().to_string(),
            ),
            None => crate::DEFAULT_SCENE_NAME.to_string(),
        }
    }

    pub fn is_dirty(&self) -> bool {
        self.state_id != self.saved_state_id
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Applies an edit, recording undo; edits of one drag coalesce into one step. An edit
    /// that would break a validity rule is refused and changes nothing (the value being
    /// typed keeps its last valid one); the refusal stays in `refusal` for the inspector.
    pub fn apply(&mut self, edit: Edit) -> Result<(), Refusal> {
        let key = edit.coalesce_key();
        let merge = key.is_some() && key == self.gesture;
        match apply_checked(&self.scene, &self.problems, edit) {
            Ok((scene, after, problems)) => {
                let before = std::mem::replace(&mut self.scene, scene);
                self.problems = problems;
                self.refusal = None;
                if !merge {
                    self.push_undo(before);
                    self.state_id = self.next_state_id;
                    self.next_state_id += 1;
                }
                self.redo.clear();
                self.gesture = key;
                self.generation += 1;
                match after {
                    After::Keep => {}
                    After::SelectNode(id) => self.selection = Some(Selection::Node(id)),
                    After::ClearSelection => self.selection = None,
                }
                self.fix_selection();
                Ok(())
            }
            Err(refusal) => {
                self.refusal = Some(refusal.clone());
                Err(refusal)
            }
        }
    }

    /// Nodes in a state an edit passes through but a file cannot hold (a TriangleMesh with
    /// no file chosen yet), with what is missing. Saving waits until there are none.
    pub fn incomplete(&self) -> impl Iterator<Item = &Problem> {
        self.problems.iter().filter(|p| p.incomplete)
    }

    /// Ends the current drag: the next edit starts a new undo step.
    pub fn end_gesture(&mut self) {
        self.gesture = None;
    }

    fn push_undo(&mut self, scene: Scene) {
        self.undo.push(Snapshot {
            scene,
            state_id: self.state_id,
        });
        if self.undo.len() > MAX_UNDO {
            self.undo.remove(0);
        }
    }

    pub fn undo(&mut self) -> bool {
        let Some(prev) = self.undo.pop() else {
            return false;
        };
        let cur = std::mem::replace(&mut self.scene, prev.scene);
        self.redo.push(Snapshot {
            scene: cur,
            state_id: self.state_id,
        });
        self.state_id = prev.state_id;
        self.after_history_move();
        true
    }

    pub fn redo(&mut self) -> bool {
        let Some(next) = self.redo.pop() else {
            return false;
        };
        let cur = std::mem::replace(&mut self.scene, next.scene);
        self.undo.push(Snapshot {
            scene: cur,
            state_id: self.state_id,
        });
        self.state_id = next.state_id;
        self.after_history_move();
        true
    }

    /// Names the present state, for [`Document::revert_to`].
    pub fn history_mark(&self) -> u64 {
        self.state_id
    }

    /// Takes back every step made since `mark` without leaving them to redo: Esc during a
    /// drag, which then never happened. False (and nothing changes) when `mark` is not in
    /// the history or is the present state.
    pub fn revert_to(&mut self, mark: u64) -> bool {
        if self.state_id == mark || !self.undo.iter().any(|s| s.state_id == mark) {
            return false;
        }
        while self.state_id != mark {
            let Some(prev) = self.undo.pop() else { break };
            self.scene = prev.scene;
            self.state_id = prev.state_id;
        }
        self.after_history_move();
        true
    }

    fn after_history_move(&mut self) {
        self.problems = check_scene(&self.scene);
        self.refusal = None;
        self.gesture = None;
        self.generation += 1;
        self.fix_selection();
    }

    /// Selects something (or nothing); a selection that points at nothing in the scene is
    /// dropped. The one way the app and the panels change the selection.
    pub fn select(&mut self, selection: Option<Selection>) {
        self.selection = selection;
        self.fix_selection();
    }

    /// Sets a TriangleMesh's `obj_file` and (re)reads that file from disk, as one edit: the
    /// mesh is read again even when the name is unchanged (the file may have changed), and
    /// a file that does not load leaves the node with the error. Relative names resolve from
    /// the document's folder. Blocking; the window reads on a thread with [`read_mesh`] and
    /// [`Self::set_mesh`].
    pub fn load_mesh(&mut self, node: NodeId, obj_file: String) -> Result<(), Refusal> {
        let base = self.path.as_deref().and_then(Path::parent);
        let mesh = read_mesh(&obj_file, base, &mut self.mesh_cache);
        self.set_mesh(node, obj_file, mesh)
    }

    /// A TriangleMesh's file and the mesh read from it (or why not), as one edit.
    pub fn set_mesh(
        &mut self,
        node: NodeId,
        obj_file: String,
        mesh: MeshSlot,
    ) -> Result<(), Refusal> {
        self.apply(Edit::SetNodeKind {
            node,
            kind: NodeKind::TriangleMesh { obj_file, mesh },
        })
    }

    /// Drops a selection that no longer points at anything.
    fn fix_selection(&mut self) {
        let ok = match self.selection {
            None
            | Some(
                Selection::Camera
                | Selection::Lights
                | Selection::Background
                | Selection::Materials,
            ) => true,
            Some(Selection::Light(i)) => i < self.scene.lights().len(),
            Some(Selection::Material(i)) => i < self.scene.materials.len(),
            Some(Selection::Node(id)) => self.scene.graph.path_to(id).is_some(),
        };
        if !ok {
            self.selection = None;
        }
    }

    /// Opens a file now (blocking; the app reads files on a thread, see `crate::gui::loading`).
    /// A file that cannot be read at all leaves the current scene open and reports why;
    /// per-node errors (a missing OBJ) open the scene and report them.
    pub fn open(&mut self, path: &Path) -> Result<(), OpenError> {
        let read = read_scene_file(path, std::mem::take(&mut self.mesh_cache));
        self.install(read)
    }

    /// Replaces the document by a scene read with [`read_scene_file`], adopting its mesh
    /// cache; a file that could not be read leaves the scene and reports why.
    pub fn install(&mut self, read: SceneRead) -> Result<(), OpenError> {
        let SceneRead {
            path,
            outcome,
            cache,
        } = read;
        match outcome {
            Ok(Opened {
                scene,
                messages,
                lost_comments,
            }) => {
                let generation = self.generation + 1;
                *self = Document::new(scene, Some(path));
                self.mesh_cache = cache;
                for (severity, m) in messages {
                    self.messages.push(Level::from(severity), m);
                }
                self.lost_comments = lost_comments;
                // Generations stay monotonic across documents: the worker compares them.
                self.generation = generation;
                Ok(())
            }
            Err(messages) => {
                self.mesh_cache = cache;
                self.messages.clear();
                for m in &messages {
                    self.messages.error(m.clone());
                }
                Err(OpenError(messages))
            }
        }
    }

    /// What saving to `path` would lose or leave unfixed, one line each, to show before or
    /// on saving: comments of the opened file that cannot be kept, and relative mesh paths
    /// that cannot be rewritten for `path`'s folder.
    pub fn save_warnings(&self, path: &Path) -> Vec<String> {
        let mut scene = self.scene.clone();
        let mut out = self.lost_comments.clone();
        out.extend(tracelab_core::rebase_mesh_paths(
            &mut scene,
            &self.folder(),
            &folder_of(path),
        ));
        out
    }

    /// Where relative `obj_file` paths of the document resolve from: its file's folder, or
    /// the current folder for a scene never saved.
    fn folder(&self) -> PathBuf {
        self.path
            .as_deref()
            .map_or_else(|| PathBuf::from("."), folder_of)
    }

    /// Writes the scene atomically (temporary file + rename) and marks it saved. Relative
    /// mesh paths are rewritten for the new folder first, in the whole history, so they keep
    /// naming the same files from there (and after an undo).
    ///
    /// Nothing is written while a node is incomplete or a rule is broken, or when the text
    /// would not read back as this document: the error says what to fix.
    pub fn save_as(&mut self, path: &Path) -> Result<(), SaveError> {
        let (from, to) = (self.folder(), folder_of(path));
        let mut scene = self.scene.clone();
        tracelab_core::rebase_mesh_paths(&mut scene, &from, &to);
        let text = self.checked_text(&scene, path)?;
        crate::io::write_atomic(path, text.as_bytes()).map_err(|source| SaveError::Write {
            path: path.to_path_buf(),
            source,
        })?;
        self.scene = scene;
        self.problems = check_scene(&self.scene);
        for s in self.undo.iter_mut().chain(self.redo.iter_mut()) {
            tracelab_core::rebase_mesh_paths(&mut s.scene, &from, &to);
        }
        self.path = Some(path.to_path_buf());
        // Those comments are gone from the file now; the next save has none to lose.
        self.lost_comments.clear();
        self.saved_state_id = self.state_id;
        self.disk_stamp = modified(path);
        Ok(())
    }

    /// The text Save As `path` would write, or why it would write nothing (see
    /// [`Document::save_as`]); writes nothing itself.
    pub fn text_for(&mut self, path: &Path) -> Result<String, SaveError> {
        let mut scene = self.scene.clone();
        tracelab_core::rebase_mesh_paths(&mut scene, &self.folder(), &folder_of(path));
        self.checked_text(&scene, path)
    }

    /// The checked writer's text for `scene` (the document rebased for `path`), read back as
    /// the file at `path` would be (meshes are not loaded: what they are is not written), and
    /// required to be the same document.
    fn checked_text(&mut self, scene: &Scene, path: &Path) -> Result<String, SaveError> {
        let name = path.display().to_string();
        let text =
            tracelab_core::try_write_scene(scene).map_err(|problems| SaveError::BreaksRules {
                path: path.to_path_buf(),
                fix: problems.into_iter().map(|p| p.message).collect(),
            })?;
        tracelab_core::format::check_reads_back(&text).map_err(|source| SaveError::TooLarge {
            path: path.to_path_buf(),
            source,
        })?;
        let back = tracelab_core::parse_scene_unresolved(text.as_bytes(), &name);
        let why = match back.scene {
            // Node errors (an OBJ that does not load) open too, as they did here.
            Some(read) => scene.reads_back_as(&read).err().map(|e| e.to_string()),
            None => Some(format!("it would not open again:\n{}", back.diagnostics)),
        };
        match why {
            Some(why) => Err(SaveError::WouldNotReadBack {
                path: path.to_path_buf(),
                why,
            }),
            None => Ok(text),
        }
    }

    pub fn save(&mut self) -> Result<(), SaveError> {
        match self.path.clone() {
            Some(p) => self.save_as(&p),
            None => Err(SaveError::NoFile),
        }
    }

    /// True when the file on disk changed since it was read or written.
    pub fn changed_on_disk(&self) -> bool {
        match (&self.path, self.disk_stamp) {
            (Some(p), Some(stamp)) => modified(p).is_some_and(|m| m != stamp),
            _ => false,
        }
    }
}

fn folder_of(file: &Path) -> PathBuf {
    file.parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

fn modified(p: &Path) -> Option<SystemTime> {
    std::fs::metadata(p).and_then(|m| m.modified()).ok()
}

#[cfg(test)]
mod tests {
    use super::edit::Edit;
    use super::*;
    use crate::test_support::names_in;
    use tracelab_core::NodeKind;

    fn temp_dir(name: &str) -> PathBuf {
        let d = crate::test_support::temp_dir("state", name);
        std::fs::create_dir_all(d.join("scenes")).expect("dirs");
        std::fs::create_dir_all(d.join("out/sub")).expect("dirs");
        d
    }

    fn obj_file(scene: &Scene) -> Option<String> {
        scene.graph.iter().find_map(|(_, n)| match &n.kind {
            NodeKind::TriangleMesh { obj_file, .. } => Some(obj_file.clone()),
            _ => None,
        })
    }

    const SCENE: &str = "# header\nPerspectiveCamera { center 3 3 5 direction -3 -3 -5 up 0 1 0 angle 40 }\nMaterials { numMaterials 1 Material { diffuseColor 1 1 1 } }\nGroup { numObjects 1 MaterialIndex 0 TriangleMesh { obj_file mesh.obj } }\n";

    #[test]
    fn save_as_into_a_sub_folder_rewrites_mesh_paths_and_keeps_comments() {
        let d = temp_dir("save-as");
        let cube = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/cube.obj");
        std::fs::copy(cube, d.join("scenes/mesh.obj")).expect("obj");
        std::fs::write(d.join("scenes/s.txt"), SCENE).expect("scene");
        let mut doc = Document::new(Scene::default(), None);
        doc.open(&d.join("scenes/s.txt")).expect("opens");
        let root = doc.scene.graph.root();
        doc.apply(Edit::SetNodeMaterial {
            node: doc.scene.graph.node(root).children[0],
            material: None,
        })
        .expect("an edit to undo");
        let out = d.join("out/sub/s.txt");
        assert!(doc.save_warnings(&out).is_empty());
        doc.save_as(&out).expect("saves");
        let text = std::fs::read_to_string(&out).expect("saved");
        assert!(text.starts_with("# header\n"), "{text}");
        assert!(text.contains("obj_file ../../scenes/mesh.obj\n"), "{text}");
        // The saved file finds its mesh from its own folder (the tests' working folder has none).
        let (saved, _) = tracelab_core::load_scene(&out, &mut MeshCache::new())
            .into_result()
            .expect("loads");
        assert!(saved.graph.iter().any(
            |(_, n)| matches!(&n.kind, NodeKind::TriangleMesh { mesh, .. } if mesh.mesh().is_some())
        ));
        // The document and its history now speak relative to the new folder.
        assert_eq!(
            obj_file(&doc.scene).as_deref(),
            Some("../../scenes/mesh.obj")
        );
        assert!(doc.undo());
        assert_eq!(
            obj_file(&doc.scene).as_deref(),
            Some("../../scenes/mesh.obj")
        );
    }

    /// Save wrote canonical text of any length; a scene nested 180,000 deep gives 74 MB,
    /// more than the 64 MiB tracelab reads, so the saved file could not be opened again.
    #[test]
    fn save_refuses_text_longer_than_a_scene_file_tracelab_reads() {
        let d = temp_dir("too-large");
        let depth = 180_000;
        let text = format!(
            "OrthographicCamera{{center 0 0 10 direction 0 0 -1 up 0 1 0 size 5}}\n\
             Materials{{numMaterials 1 Material{{diffuseColor 1 0 0}}}}\n{}Sphere{{center 0 0 0 radius 1}}{}",
            "Group{numObjects 1\n".repeat(depth),
            "}".repeat(depth)
        );
        std::fs::write(d.join("scenes/deep.txt"), text).expect("scene");
        let mut doc = Document::new(Scene::default(), None);
        doc.open(&d.join("scenes/deep.txt")).expect("opens");
        let out = d.join("out/deep.txt");
        let e = doc.save_as(&out).expect_err("too large to read back");
        assert!(matches!(e, SaveError::TooLarge { .. }), "{e}");
        assert!(
            e.to_string()
                .contains("MiB, more than the 64 MiB tracelab reads as a scene"),
            "{e}"
        );
        assert!(!out.exists());
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn save_warnings_name_comments_the_save_drops() {
        let d = temp_dir("lost");
        let text = SCENE
            .replace("angle 40", "angle # forty\n 40")
            .replace("mesh.obj", "/nonexistent/mesh.obj");
        std::fs::write(d.join("scenes/s.txt"), text).expect("scene");
        let mut doc = Document::new(Scene::default(), None);
        doc.open(&d.join("scenes/s.txt"))
            .expect("opens with a missing mesh");
        let w = doc.save_warnings(&d.join("scenes/s.txt"));
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].contains("s.txt:2:") && w[0].contains("comment"),
            "{w:?}"
        );
    }

    fn empty_dir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("tracelab-state-io-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("temp dir");
        d
    }

    #[test]
    fn an_incomplete_mesh_is_listed_and_keeps_save_from_writing_until_it_names_a_file() {
        let d = empty_dir("incomplete");
        let p = d.join("scene.txt");
        std::fs::write(&p, crate::DEFAULT_SCENE).expect("write");
        let mut doc = Document::builtin();
        doc.open(&p).expect("open");
        let root = doc.scene.graph.root();
        let mesh = |obj_file: &str| NodeKind::TriangleMesh {
            obj_file: obj_file.into(),
            mesh: tracelab_core::MeshSlot::Failed(String::new()),
        };
        doc.apply(Edit::AddNode {
            parent: root,
            kind: mesh(""),
        })
        .expect("an incomplete node is allowed");
        let Some(Selection::Node(id)) = doc.selection else {
            panic!("the new node is selected")
        };
        let incomplete: Vec<_> = doc
            .incomplete()
            .map(|p| (p.node(), p.reason.clone()))
            .collect();
        assert_eq!(
            incomplete,
            [(Some(id), "TriangleMesh: no OBJ file chosen yet".to_string())]
        );
        let e = doc.save().expect_err("nothing to write yet").to_string();
        assert!(
            e.contains("not saved") && e.contains("no OBJ file chosen yet"),
            "{e}"
        );
        assert_eq!(
            std::fs::read_to_string(&p).expect("read"),
            crate::DEFAULT_SCENE
        );
        // A name that cannot be written is refused outright; a missing file is only a node error.
        let refused = doc
            .apply(Edit::SetNodeKind {
                node: id,
                kind: mesh("my mesh.obj"),
            })
            .expect_err("a space");
        assert_eq!(
            (refused.place, refused.field),
            (
                Some(tracelab_core::Place::Node(id)),
                Some(tracelab_core::Field::ObjFile)
            )
        );
        doc.apply(Edit::SetNodeKind {
            node: id,
            kind: mesh("elsewhere.obj"),
        })
        .expect("a name");
        assert_eq!(doc.incomplete().count(), 0);
        doc.save().expect("saves");
        assert!(
            std::fs::read_to_string(&p)
                .expect("read")
                .contains("obj_file elsewhere.obj")
        );
    }

    #[cfg(unix)]
    #[test]
    fn save_keeps_a_private_files_mode() {
        use std::os::unix::fs::PermissionsExt;
        let d = empty_dir("mode");
        let p = d.join("scene.txt");
        std::fs::write(&p, crate::DEFAULT_SCENE).expect("write");
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o600)).expect("chmod");
        let mut doc = Document::builtin();
        doc.open(&p).expect("open");
        doc.save().expect("save");
        assert_eq!(
            std::fs::metadata(&p).expect("meta").permissions().mode() & 0o7777,
            0o600
        );
        assert_eq!(names_in(&d), ["scene.txt"]);
    }

    #[cfg(unix)]
    #[test]
    fn save_writes_through_a_symlink_to_its_target() {
        let d = empty_dir("link");
        std::fs::create_dir(d.join("real")).expect("mkdir");
        std::fs::write(d.join("real/scene.txt"), crate::DEFAULT_SCENE).expect("write");
        std::os::unix::fs::symlink("real/scene.txt", d.join("link.txt")).expect("symlink");
        let mut doc = Document::builtin();
        doc.open(&d.join("link.txt")).expect("open");
        doc.scene.background.color = Some(glam::Vec3::new(0.25, 0.5, 0.75));
        doc.save().expect("save");
        assert!(
            std::fs::symlink_metadata(d.join("link.txt"))
                .expect("meta")
                .file_type()
                .is_symlink()
        );
        let text = std::fs::read_to_string(d.join("real/scene.txt")).expect("read");
        assert!(text.contains("0.25 0.5 0.75"), "{text}");
        assert_eq!(names_in(&d), ["link.txt", "real"]);
        assert_eq!(names_in(&d.join("real")), ["scene.txt"]);
    }

    #[test]
    fn a_failed_save_keeps_the_old_file_the_path_and_no_temporary_file() {
        let d = empty_dir("fail");
        let p = d.join("scene.txt");
        std::fs::write(&p, crate::DEFAULT_SCENE).expect("write");
        let mut doc = Document::builtin();
        doc.open(&p).expect("open");
        let e = doc
            .save_as(&d.join("gone/scene.txt"))
            .expect_err("no such folder")
            .to_string();
        assert!(e.contains("cannot write"), "{e}");
        assert_eq!(doc.path.as_deref(), Some(p.as_path()));
        assert_eq!(
            std::fs::read_to_string(&p).expect("read"),
            crate::DEFAULT_SCENE
        );
        assert_eq!(names_in(&d), ["scene.txt"]);
    }

    /// A folder that refuses new files even to root (`chattr +i`, ext4 and similar), or to
    /// anyone else (mode 0555); undone on drop.
    #[cfg(unix)]
    struct LockedDir(PathBuf);

    #[cfg(unix)]
    impl Drop for LockedDir {
        fn drop(&mut self) {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::process::Command::new("chattr")
                .arg("-i")
                .arg(&self.0)
                .status();
            let _ = std::fs::set_permissions(&self.0, std::fs::Permissions::from_mode(0o755));
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_save_into_a_locked_folder_fails_and_keeps_the_old_file() {
        use std::os::unix::fs::PermissionsExt;
        let d = empty_dir("locked");
        let p = d.join("scene.txt");
        std::fs::write(&p, "old text").expect("write");
        let mut doc = Document::builtin();
        doc.path = Some(p.clone());
        let lock = LockedDir(d.clone());
        std::fs::set_permissions(&d, std::fs::Permissions::from_mode(0o555)).expect("chmod");
        let _ = std::process::Command::new("chattr")
            .arg("+i")
            .arg(&d)
            .status();
        let probe = std::fs::File::create(d.join("probe")).is_ok();
        let _ = std::fs::remove_file(d.join("probe"));
        assert!(
            !probe,
            "cannot make a folder that refuses new files here (root without chattr +i): this test needs mode 0555 to hold, or chattr"
        );
        assert!(doc.save().is_err(), "saving into a locked folder fails");
        drop(lock);
        assert_eq!(std::fs::read_to_string(&p).expect("read"), "old text");
        assert_eq!(names_in(&d), ["scene.txt"]);
    }
}
