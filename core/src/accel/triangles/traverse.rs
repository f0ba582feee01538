//! One ray through the tree: the closest hit (the SSE slab test anywhere, the AVX kernels
//! where the CPU has them), whether there is any hit (shadow rays) and every hit (for CSG).

use glam::{Vec3A, Vec4};

#[cfg(target_arch = "x86_64")]
use super::avx::{self, LeafRay, caller};
#[cfg(target_arch = "x86_64")]
use super::avx512;
use super::{SLAB_WIDEN, TriangleBvh, TriangleHit, finite_ray, has_avx, has_avx512};
use crate::accel::wide::{self, Child, Node8, RayStack, StackEntry, WIDTH};
use crate::geometry::Ray;

/// A ray set up for the slab tests: origin, direction, reciprocal direction, and per axis
/// whether it runs toward -axis (so it enters a box through the max plane).
///
/// 16-byte `Vec3A`s, not `Vec3`s: the tests broadcast single components, and 12-byte fields
/// were loaded as 16 bytes spanning two earlier stores, a failed store forward on every ray
/// (`docs/perf.md`).
pub(super) struct SlabRay {
    pub(super) o: Vec3A,
    pub(super) d: Vec3A,
    pub(super) inv: Vec3A,
    pub(super) toward_neg: [bool; 3],
}

impl SlabRay {
    #[inline(always)]
    pub(super) fn new(o: Vec3A, d: Vec3A) -> Self {
        // One packed division rather than three scalar ones on every ray's critical path.
        let inv = d.recip();
        SlabRay {
            o,
            d,
            inv,
            toward_neg: [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0],
        }
    }

    /// Whether the ray meets the box [lo, hi] within [t_min, t_max], widened as `slab8`
    /// widens so it never culls a box the traversal would enter.
    #[inline(always)]
    fn enters(&self, lo: Vec3A, hi: Vec3A, t_min: f32, t_max: f32) -> bool {
        let (near, far) = crate::accel::slab::span(lo, hi, self.o, self.inv, t_min, t_max);
        near <= far * SLAB_WIDEN
    }

    /// Entry distances of all eight slots into `t_enter`; bit i of the result is set when
    /// slot i is entered within [t_min, t_max]. Two SSE halves; `avx::slab8` is one register.
    #[inline(always)]
    pub(super) fn slab8(
        &self,
        n: &Node8,
        t_min: f32,
        t_max: f32,
        t_enter: &mut [f32; WIDTH],
    ) -> u32 {
        let (nx, fx) = n.entry_exit(0, self.toward_neg[0]);
        let (ny, fy) = n.entry_exit(1, self.toward_neg[1]);
        let (nz, fz) = n.entry_exit(2, self.toward_neg[2]);
        let (o, inv) = (self.o, self.inv);
        let (ox, oy, oz) = (Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z));
        let (ix, iy, iz) = (Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z));
        let (t0, t1) = (Vec4::splat(t_min), Vec4::splat(t_max));
        let mut mask = 0u32;
        let mut near = [Vec4::ZERO; 2];
        for h in 0..2 {
            // maxps/minps return the second operand when the first is NaN (0 * inf on an
            // axis-parallel ray), so that axis drops out instead of poisoning the result.
            let a = ((nx[h] - ox) * ix)
                .max((ny[h] - oy) * iy)
                .max(((nz[h] - oz) * iz).max(t0));
            let b = ((fx[h] - ox) * ix)
                .min((fy[h] - oy) * iy)
                .min(((fz[h] - oz) * iz).min(t1));
            mask |= a.cmple(b * SLAB_WIDEN).bitmask() << (4 * h);
            near[h] = a;
        }
        let (lo, hi) = t_enter.split_at_mut(4);
        lo.copy_from_slice(&near[0].to_array());
        hi.copy_from_slice(&near[1].to_array());
        mask
    }
}

#[cfg(target_arch = "x86_64")]
impl LeafRay for SlabRay {
    #[inline(always)]
    fn origin(&self) -> Vec3A {
        self.o
    }
    #[inline(always)]
    fn direction(&self) -> Vec3A {
        self.d
    }
}

/// A `SlabRay` in the octant of direction signs `NX`, `NY`, `NZ` (true: toward -axis), as
/// the leaf tests read it: the same ray, a type per octant and per caller `M` (the walk's
/// ray type and move, `closest_hit_of`), so that each octant's walk (`TriangleBvh::
/// by_octant`) in each copy of the walk has its own copy of the leaf test to inline. With
/// eight walks calling one copy, LLVM left it a call, and the walks spilled their registers
/// around it; without `M`, two copies of the walk (two moves) shared the leaf tests, and
/// left them calls again (the editor's Whitted frames up to 5% slower, `docs/perf.md`).
#[cfg(target_arch = "x86_64")]
struct InOctant<'a, M, const NX: bool, const NY: bool, const NZ: bool>(
    &'a SlabRay,
    std::marker::PhantomData<fn() -> M>,
);

#[cfg(target_arch = "x86_64")]
impl<M, const NX: bool, const NY: bool, const NZ: bool> LeafRay for InOctant<'_, M, NX, NY, NZ> {
    #[inline(always)]
    fn origin(&self) -> Vec3A {
        self.0.o
    }
    #[inline(always)]
    fn direction(&self) -> Vec3A {
        self.0.d
    }
}

/// Where the traversal goes from a node whose slots in `mask` the ray enters, at distances
/// `t_enter`: returns the nearest slot's entry to visit now and pushes the others so the
/// nearest of them pops first. One slot: itself; two: the far one pushed, no sort (the lower
/// slot wins a tie); more: all pushed, the top insertion-sorted, the nearest popped.
/// `entry(slot)` is what the stack holds for a slot. None when `mask` is empty.
///
/// Two slots take a branch on their order, not a conditional move: with the move, the next
/// node's load waited for the two entry distances' round trip through `t_enter`, and single
/// rays were up to 4% slower (`docs/perf.md`; one path for one slot and two: 6-10% slower).
#[inline(always)]
pub(super) fn nearest_first<E: StackEntry>(
    mask: u32,
    t_enter: &[f32; WIDTH],
    stack: &mut RayStack<E>,
    entry: impl Fn(usize) -> E,
) -> Option<E> {
    if mask == 0 {
        return None;
    }
    let i = mask.trailing_zeros() as usize;
    let rest = mask & (mask - 1);
    if rest == 0 {
        return Some(entry(i));
    }
    if rest & (rest - 1) == 0 {
        let j = rest.trailing_zeros() as usize;
        if t_enter[i] <= t_enter[j] {
            stack.push(entry(j));
            return Some(entry(i));
        }
        stack.push(entry(i));
        return Some(entry(j));
    }
    let mut m = mask;
    let mut k = 0;
    while m != 0 {
        let j = m.trailing_zeros() as usize;
        m &= m - 1;
        stack.push(entry(j));
        k += 1;
    }
    stack.sort_top(k);
    stack.pop()
}

/// The closest-hit traversal, generic over the 8-box test and the leaf test, and inlined
/// into the function that picks them so each copy is compiled for the instruction set that
/// function enables (`walk_portable`, `walk_avx`, `walk_avx512`).
///
/// With `FIRST` it returns at the first leaf hit instead (`any_hit`). Until that hit, t_best
/// is still t_max, so it takes the very steps the closest-hit walk takes: the same boxes,
/// the same leaves, the same tests. It finds a hit exactly when the closest-hit walk does.
/// (An unordered walk would not: `pop_within` drops a pushed child entered past t_max,
/// while the nearest child, visited without a pop, is entered up to `SLAB_WIDEN` past it.)
#[inline(always)]
fn closest_hit_with<const FIRST: bool>(
    bvh: &TriangleBvh,
    r: &SlabRay,
    t_min: f32,
    t_max: f32,
    slab8: impl Fn(&SlabRay, &Node8, f32, f32, &mut [f32; WIDTH]) -> u32,
    leaf: impl Fn(&SlabRay, usize, usize, f32, f32) -> Option<(f32, usize)>,
) -> Option<TriangleHit> {
    // A NaN or infinite ray (an overflowing object-space transform) makes every slab test
    // NaN, which would enter the empty slots, whose child is the root: endless.
    if bvh.is_empty() || !finite_ray(r.o, r.d) || !r.enters(bvh.root_lo, bvh.root_hi, t_min, t_max)
    {
        return None;
    }
    let mut t_best = t_max;
    let mut best = usize::MAX;
    let mut stack = RayStack::new();
    let mut t_enter = [0.0f32; WIDTH];
    let mut cur: Child = bvh.start(&mut stack, |c| (c, t_min));
    loop {
        if wide::is_leaf(cur) {
            let (first, count) = wide::leaf_range(cur);
            if let Some((t, k)) = leaf(r, first, count, t_min, t_best) {
                if FIRST {
                    return Some(TriangleHit {
                        t,
                        triangle: bvh.ids[k],
                    });
                }
                t_best = t;
                best = k;
            }
        } else {
            let n = bvh.node(cur);
            let mask = slab8(r, n, t_min, t_best, &mut t_enter);
            let entry = |s: usize| (n.child_at(s), t_enter[s]);
            if let Some((c, _)) = nearest_first(mask, &t_enter, &mut stack, entry) {
                cur = c;
                continue;
            }
        }
        match stack.pop_within(t_best) {
            Some((c, _)) => cur = c,
            None => {
                return (best != usize::MAX).then(|| TriangleHit {
                    t: t_best,
                    triangle: bvh.ids[best],
                });
            }
        }
    }
}

impl TriangleBvh {
    /// Closest hit in (t_min, t_max). Two-sided Möller–Trumbore.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<TriangleHit> {
        self.closest_hit(ray.origin.into(), ray.direction.into(), t_min, t_max)
    }

    /// `intersect` for a ray given as 16-byte vectors, the form the traversal keeps. Callers
    /// that build the ray just before should pass the move instead (`closest_hit_of`).
    #[inline]
    pub fn closest_hit(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<TriangleHit> {
        self.closest_hit_of(&(o, d), |&r| r, t_min, t_max)
    }

    /// The closest hit of the ray `to_object` makes from `ray` (a world ray moved into the
    /// mesh's space, or a ray as it is), in (t_min, t_max). The move is inlined into the
    /// function compiled for the CPU's instruction set, with the walk: a `Vec3A` passed to
    /// such a function goes through memory, on the chain each ray starts with (single rays
    /// 2-5% faster on Zen 5 than the moved ray passed in, `docs/perf.md`).
    #[inline(always)]
    pub fn closest_hit_of<R>(
        &self,
        ray: &R,
        to_object: impl Fn(&R) -> (Vec3A, Vec3A),
        t_min: f32,
        t_max: f32,
    ) -> Option<TriangleHit> {
        self.hit_of::<false, R>(ray, to_object, t_min, t_max)
    }

    /// Whether any triangle is hit with t in (t_min, t_max): a shadow ray's question. It
    /// stops at the first hit found, and answers exactly `closest_hit(..).is_some()`, on
    /// every instruction set (the same walk up to that hit, the same triangle test).
    #[inline]
    pub fn any_hit(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> bool {
        self.any_hit_of(&(o, d), |&r| r, t_min, t_max)
    }

    /// `any_hit` of the ray `to_object` makes from `ray`, the move inlined as in
    /// `closest_hit_of`.
    #[inline(always)]
    pub fn any_hit_of<R>(
        &self,
        ray: &R,
        to_object: impl Fn(&R) -> (Vec3A, Vec3A),
        t_min: f32,
        t_max: f32,
    ) -> bool {
        self.hit_of::<true, R>(ray, to_object, t_min, t_max)
            .is_some()
    }

    /// `closest_hit_of`, or with `FIRST` the first hit found (`any_hit_of`), on the widest
    /// instruction set this CPU has and `TRACELAB_SIMD` allows (`crate::simd`).
    #[inline(always)]
    fn hit_of<const FIRST: bool, R>(
        &self,
        ray: &R,
        to_object: impl Fn(&R) -> (Vec3A, Vec3A),
        t_min: f32,
        t_max: f32,
    ) -> Option<TriangleHit> {
        #[cfg(target_arch = "x86_64")]
        if has_avx512() {
            #[allow(unsafe_code)]
            // SAFETY: the CPU has AVX-512 F and VL, checked just above.
            return unsafe { self.walk_avx512::<FIRST, R, _>(ray, to_object, t_min, t_max) };
        }
        #[cfg(target_arch = "x86_64")]
        if has_avx() {
            #[allow(unsafe_code)]
            // SAFETY: the CPU has AVX, checked just above (std caches the answer).
            return unsafe { self.walk_avx::<FIRST, R, _>(ray, to_object, t_min, t_max) };
        }
        let (o, d) = to_object(ray);
        self.walk_portable::<FIRST>(o, d, t_min, t_max)
    }

    /// `hit_of`'s walk with SSE only (any x86-64, and the fallback elsewhere). Not inlined:
    /// inlined, this traversal (unused where there is AVX) sat in the renderer's hot
    /// function, and its shape changed the register allocation of that function's hot part.
    #[inline(never)]
    pub(super) fn walk_portable<const FIRST: bool>(
        &self,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<TriangleHit> {
        closest_hit_with::<FIRST>(
            self,
            &SlabRay::new(o, d),
            t_min,
            t_max,
            SlabRay::slab8,
            |r, first, count, t_min, t_best| self.leaf_scalar(r, first, count, t_min, t_best),
        )
    }

    /// `hit_of`'s walk with the AVX kernels: the eight slots in one register, a leaf's
    /// triangles in one test.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    pub(super) fn walk_avx<const FIRST: bool, R, F: Fn(&R) -> (Vec3A, Vec3A)>(
        &self,
        ray: &R,
        to_object: F,
        t_min: f32,
        t_max: f32,
    ) -> Option<TriangleHit> {
        let (o, d) = to_object(ray);
        let r = SlabRay::new(o, d);
        #[allow(unsafe_code)]
        // SAFETY: this function enables AVX, what `by_octant` needs.
        unsafe {
            self.by_octant::<(R, F), FIRST, false>(&r, t_min, t_max)
        }
    }

    /// `hit_of`'s walk with AVX-512 (F and VL): `walk_avx`'s walk and 8-box test compiled for
    /// AVX-512 (32 vector registers, compares into mask registers), and the leaf test with
    /// mask registers (`avx512::leaf8`). Both give `walk_avx`'s bits; 3-4% faster than it on
    /// the bunnies (`docs/perf.md`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl")]
    fn walk_avx512<const FIRST: bool, R, F: Fn(&R) -> (Vec3A, Vec3A)>(
        &self,
        ray: &R,
        to_object: F,
        t_min: f32,
        t_max: f32,
    ) -> Option<TriangleHit> {
        let (o, d) = to_object(ray);
        let r = SlabRay::new(o, d);
        #[allow(unsafe_code)]
        // SAFETY: this function enables AVX-512 F and VL, what `by_octant` needs.
        unsafe {
            self.by_octant::<(R, F), FIRST, true>(&r, t_min, t_max)
        }
    }

    /// The AVX walk (`WIDE`: with the AVX-512 leaf test) for the ray's octant: one copy of
    /// the walk per combination of direction signs, so each 8-box test reads its entry and
    /// exit rows at offsets fixed when compiled rather than chosen per node (tinybvh's
    /// `BVH8_CPU` does the same). On Zen 5, single rays on the Stanford bunny and the
    /// dragon +2-3% with AVX-512 (2-4% more once each copy inlined its own leaf test,
    /// `InOctant`) and +10-11% with AVX (16 vector registers: a copy per octant needs fewer
    /// of them), the editor's Whitted frames even or faster (`docs/perf.md`). Choosing the
    /// rows by blends in one copy gained nothing, so it is not the rows alone.
    /// `FIRST`: stop at the first hit (`any_hit`). `M`: the caller's ray type and move, so
    /// each caller's walks get leaf tests of their own (`InOctant`).
    ///
    /// # Safety
    /// The CPU must have AVX, and AVX-512 F and VL when `WIDE`; called only from functions
    /// that enable them, into which it is inlined.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn by_octant<M, const FIRST: bool, const WIDE: bool>(
        &self,
        r: &SlabRay,
        t_min: f32,
        t_max: f32,
    ) -> Option<TriangleHit> {
        #[allow(unsafe_code)]
        // SAFETY: the caller's features, as this function's contract says.
        unsafe {
            match r.toward_neg {
                [false, false, false] => {
                    self.walk::<M, FIRST, WIDE, false, false, false>(r, t_min, t_max)
                }
                [false, false, true] => {
                    self.walk::<M, FIRST, WIDE, false, false, true>(r, t_min, t_max)
                }
                [false, true, false] => {
                    self.walk::<M, FIRST, WIDE, false, true, false>(r, t_min, t_max)
                }
                [false, true, true] => {
                    self.walk::<M, FIRST, WIDE, false, true, true>(r, t_min, t_max)
                }
                [true, false, false] => {
                    self.walk::<M, FIRST, WIDE, true, false, false>(r, t_min, t_max)
                }
                [true, false, true] => {
                    self.walk::<M, FIRST, WIDE, true, false, true>(r, t_min, t_max)
                }
                [true, true, false] => {
                    self.walk::<M, FIRST, WIDE, true, true, false>(r, t_min, t_max)
                }
                [true, true, true] => {
                    self.walk::<M, FIRST, WIDE, true, true, true>(r, t_min, t_max)
                }
            }
        }
    }

    /// `by_octant`'s walk for rays running toward -x, -y, -z where `NX`, `NY`, `NZ`.
    ///
    /// # Safety
    /// As `by_octant`.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(unsafe_code)]
    unsafe fn walk<
        M,
        const FIRST: bool,
        const WIDE: bool,
        const NX: bool,
        const NY: bool,
        const NZ: bool,
    >(
        &self,
        r: &SlabRay,
        t_min: f32,
        t_max: f32,
    ) -> Option<TriangleHit> {
        closest_hit_with::<FIRST>(
            self,
            r,
            t_min,
            t_max,
            |r, n, t_min, t_max, t_enter| {
                #[allow(unsafe_code)]
                // SAFETY: the caller has AVX (this function's contract).
                unsafe {
                    avx::slab8(n, r.o, r.inv, [NX, NY, NZ], t_min, t_max, t_enter)
                }
            },
            |r, first, count, t_min, t_best| {
                // With AVX-512 the ray typed by its octant, so each copy of the walk calls a
                // leaf test of its own, which LLVM inlines (`avx::leaf8`'s `CALLER`). Not
                // with AVX: in 16 vector registers the inlined test made the walks 1-3%
                // slower than one shared copy (`docs/perf.md`).
                let o = &InOctant::<M, NX, NY, NZ>(r, std::marker::PhantomData);
                #[allow(unsafe_code)]
                // SAFETY: the caller has AVX, and AVX-512 F and VL when WIDE (the contract).
                unsafe {
                    match (WIDE, FIRST) {
                        (true, false) => avx512::leaf8::<_, { caller::CLOSEST }>(
                            self, o, first, count, t_min, t_best,
                        ),
                        (true, true) => avx512::leaf8::<_, { caller::ANY }>(
                            self, o, first, count, t_min, t_best,
                        ),
                        (false, false) => avx::leaf8::<_, { caller::CLOSEST }>(
                            self, r, first, count, t_min, t_best,
                        ),
                        (false, true) => {
                            avx::leaf8::<_, { caller::ANY }>(self, r, first, count, t_min, t_best)
                        }
                    }
                }
            },
        )
    }

    /// The nearest hit in (t_min, t_best) among triangles first..first+count, one at a time:
    /// (t, index in leaf order). The first of equal t wins.
    #[inline(always)]
    fn leaf_scalar(
        &self,
        r: &SlabRay,
        first: usize,
        count: usize,
        t_min: f32,
        t_best: f32,
    ) -> Option<(f32, usize)> {
        let mut best = None;
        let mut t_best = t_best;
        for k in first..first + count {
            if let Some(t) = self.tri(k).hit(r.o.into(), r.d.into())
                && t > t_min
                && t < t_best
            {
                t_best = t;
                best = Some((t, k));
            }
        }
        best
    }

    /// Every hit with t in (t_min, t_max), in no particular order, appended to `out`. CSG
    /// needs all crossings of a closed mesh along a ray, not just the nearest.
    pub fn intersect_all(&self, ray: &Ray, t_min: f32, t_max: f32, out: &mut Vec<TriangleHit>) {
        if self.is_empty() {
            return;
        }
        if !finite_ray(ray.origin.into(), ray.direction.into()) {
            return; // as in `closest_hit`
        }
        let r = SlabRay::new(ray.origin.into(), ray.direction.into());
        let mut stack = RayStack::new();
        let mut t_enter = [0.0f32; WIDTH];
        let first = self.start(&mut stack, |c| (c, t_min));
        stack.push((first, t_min));
        while let Some((c, _)) = stack.pop() {
            if wide::is_leaf(c) {
                let (first, count) = wide::leaf_range(c);
                for k in first..first + count {
                    if let Some(t) = self.tri(k).hit(r.o.into(), r.d.into())
                        && t > t_min
                        && t < t_max
                    {
                        out.push(TriangleHit {
                            t,
                            triangle: self.ids[k],
                        });
                    }
                }
                continue;
            }
            let n = self.node(c);
            let mut mask = r.slab8(n, t_min, t_max, &mut t_enter);
            while mask != 0 {
                let i = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                stack.push((n.child[i], t_enter[i]));
            }
        }
    }
}
