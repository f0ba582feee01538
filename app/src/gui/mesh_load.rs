//! A TriangleMesh's OBJ read on a thread (as scene files are, see `loading`): a large mesh
//! never freezes the window. The edit is applied when the read is done.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, TryRecvError, channel};

use tracelab_core::{MeshCache, MeshSlot, NodeId};

use crate::document::read_mesh;

/// What a finished read gives back: the node, its new file name, the mesh (or why not) and
/// the cache it was read into (the document's, plus this mesh).
pub struct MeshRead {
    pub node: NodeId,
    pub obj_file: String,
    pub mesh: MeshSlot,
    pub cache: MeshCache,
}

pub struct MeshLoad {
    rx: Receiver<MeshRead>,
    node: NodeId,
    obj_file: String,
}

impl MeshLoad {
    pub fn start(
        node: NodeId,
        obj_file: String,
        base: Option<PathBuf>,
        mut cache: MeshCache,
        repaint: Arc<dyn Fn() + Send + Sync>,
    ) -> Self {
        let (tx, rx) = channel();
        let name = obj_file.clone();
        let spawned = std::thread::Builder::new()
            .name("tracelab-mesh".into())
            .spawn(move || {
                let mesh = read_mesh(&name, base.as_deref(), &mut cache);
                let _ = tx.send(MeshRead {
                    node,
                    obj_file: name,
                    mesh,
                    cache,
                });
                repaint();
            });
        let rx = match spawned {
            Ok(_) => rx,
            Err(e) => {
                // No thread to be had: the node says why, as for a file that does not load.
                let (tx, rx) = channel();
                let _ = tx.send(MeshRead {
                    node,
                    obj_file: obj_file.clone(),
                    mesh: MeshSlot::Failed(format!("cannot start reading: {e}")),
                    cache: MeshCache::new(),
                });
                rx
            }
        };
        MeshLoad { rx, node, obj_file }
    }

    /// The result, once the thread is done.
    pub fn poll(&self) -> Option<MeshRead> {
        match self.rx.try_recv() {
            Ok(r) => Some(r),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => Some(MeshRead {
                node: self.node,
                obj_file: self.obj_file.clone(),
                mesh: MeshSlot::Failed("reading stopped unexpectedly".into()),
                cache: MeshCache::new(),
            }),
        }
    }
}
