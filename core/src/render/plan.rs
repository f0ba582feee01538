//! What a render does ([`RenderPlan`]: its passes and how primary rays are traced) and what
//! may stop it ([`Cancel`]); `progressive.rs` carries it out.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// The passes' scales, coarsest first. The first is 16×: on a large mesh the first image's
/// time is mostly its sparse rays walking a cold tree (the dragon's 8× pass: 6,900 rays, 80%
/// of its time), and 16× traces a quarter of them (docs/perf.md).
pub(super) const SCALES: [u32; 5] = [16, 8, 4, 2, 1];

/// After a coarse pass, the render goes straight to the full-resolution pass when the rays
/// that pass has left would take less than this at the coarse pass's time per ray. That time
/// overstates a full pass's several times over (sparse packets, the whole frame written for
/// few rays), so the full image then follows within some tens of milliseconds, where the
/// finer previews would barely show and cost a seventh to a third of the render (docs/perf.md).
pub(super) const STRAIGHT_TO_FULL_BELOW: Duration = Duration::from_millis(250);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cancelled;

/// How primary rays reach the scene. The two give the same image bit for bit (tested on every
/// course and perf scene); `Packets` is what every render uses, `SingleRays` is there to
/// prove that and to measure the difference.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tracing {
    /// Eight neighbouring pixels at a time (`CompiledScene::intersect8`: one packet for a
    /// one-mesh scene, else one by one), shaded one by one.
    #[default]
    Packets,
    SingleRays,
}

/// Which passes a render makes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Passes {
    /// Coarse passes (one ray per 16×16 block, 8×8, 4×4, 2×2) then every pixel; straight to
    /// the full pass when a coarse one is quick.
    #[default]
    Progressive,
    /// Only the first three coarse passes (down to 4×4): what the editor renders while the
    /// mouse drags the view, refining once it stops.
    Coarse,
    /// One full-resolution pass.
    Full,
}

/// What a render does: its passes and how its primary rays are traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderPlan {
    pub passes: Passes,
    pub tracing: Tracing,
}

impl RenderPlan {
    pub const PROGRESSIVE: RenderPlan = RenderPlan {
        passes: Passes::Progressive,
        tracing: Tracing::Packets,
    };
    pub const COARSE: RenderPlan = RenderPlan {
        passes: Passes::Coarse,
        tracing: Tracing::Packets,
    };
    pub const FULL: RenderPlan = RenderPlan {
        passes: Passes::Full,
        tracing: Tracing::Packets,
    };

    /// The same plan with its primary rays traced as `tracing` says.
    pub fn traced(self, tracing: Tracing) -> RenderPlan {
        RenderPlan { tracing, ..self }
    }

    pub(super) fn schedule(&self) -> Schedule<'static> {
        let (scales, straight_to_full_below): (&[u32], _) = match self.passes {
            Passes::Progressive => (&SCALES, Some(STRAIGHT_TO_FULL_BELOW)),
            Passes::Coarse => (&SCALES[..3], None),
            Passes::Full => (&[1], None),
        };
        Schedule {
            scales,
            straight_to_full_below,
            tracing: self.tracing,
        }
    }
}

/// A plan's passes spelt out (tests give their own).
#[derive(Clone, Copy, Debug)]
pub(super) struct Schedule<'a> {
    pub scales: &'a [u32],
    /// Skip to the full pass when a pass took less than this.
    pub straight_to_full_below: Option<Duration>,
    pub tracing: Tracing,
}

/// What may stop a render between tiles: a flag (`AtomicBool`: `Err(Cancelled)` promptly
/// once it is set) or nothing ([`Uncancellable`]: its error type is empty, so a caller
/// writes `let Ok(()) = render(…)` and discards nothing).
pub trait Cancel: Sync {
    type Stop: Send;
    fn stop(&self) -> Option<Self::Stop>;
}

impl Cancel for AtomicBool {
    type Stop = Cancelled;
    #[inline]
    fn stop(&self) -> Option<Cancelled> {
        self.load(Ordering::Relaxed).then_some(Cancelled)
    }
}

/// A render nothing stops.
#[derive(Clone, Copy, Debug, Default)]
pub struct Uncancellable;

impl Cancel for Uncancellable {
    type Stop = std::convert::Infallible;
    #[inline]
    fn stop(&self) -> Option<std::convert::Infallible> {
        None
    }
}
