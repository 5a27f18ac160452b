//! What the cell-by-cell operators share: cells in compact runs with a conflict-free
//! colouring, the reduced numbering of nodes, and a deterministic parallel sum.
//!
//! Cells are taken in runs of up to [`CELLS_PER_RUN`] cells, consecutive along a Morton curve
//! of their centroids: a run gathers the values of its distinct nodes once (about a fifth of
//! its cells' node references), works on them in cache and adds its results once. Runs of
//! one colour share no node, so they add their results in parallel without conflicts, and
//! every entry receives its contributions in an order fixed by the colours and the cell
//! order alone: the result does not depend on the number of threads.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use hocurve_mesh::HighOrderMesh;
use rayon::prelude::*;

use crate::condensation::Constraints;

/// Cells per run (the unit of colouring and of parallel work), fewer when a run's node
/// references would not fit 16-bit local indices or the mesh has fewer than
/// [`MIN_RUNS`] × 128 cells.
const CELLS_PER_RUN: usize = 128;
/// Runs a mesh is cut into at least (runs of no fewer than [`MIN_CELLS_PER_RUN`] cells): a
/// colour then holds enough runs to keep every thread busy. Measured on the coarse sphere
/// (1 236 tetrahedra, p = 6, 2 threads): with 10 runs of 128 cells the two threads ran the
/// CG iterations only 1.32× faster than one.
const MIN_RUNS: usize = 128;
const MIN_CELLS_PER_RUN: usize = 8;

/// The cells of a mesh (all with `n` nodes) in coloured runs.
pub(crate) struct CellRuns {
    /// The mesh's index of the cell at each position.
    pub order: Vec<u32>,
    /// Nodes per cell.
    n: usize,
    /// Cells per run.
    run_length: usize,
    /// The distinct nodes of each run, increasing: run k's are
    /// `run_nodes[run_start[k]..run_start[k + 1]]`.
    run_start: Vec<usize>,
    run_nodes: Vec<u32>,
    /// The n nodes of the cell at each position, as positions in its run's node list.
    local: Vec<u16>,
    /// The runs of each colour, then the runs done one after the other (those that found no
    /// free colour).
    colours: Vec<Vec<u32>>,
    sequential: Vec<u32>,
}

impl CellRuns {
    /// The runs of `mesh`, whose cells all have `n` nodes (checked by the caller).
    pub fn new(mesh: &HighOrderMesh, n: usize) -> Self {
        Self::of(mesh, morton_order(mesh, |_| true), n)
    }

    /// The runs of the cells of `mesh` of shape `shape`, which have `n` nodes.
    pub fn of_shape(mesh: &HighOrderMesh, shape: hocurve_nodes::Shape, n: usize) -> Self {
        Self::of(mesh, morton_order(mesh, |c| c.kind == shape), n)
    }

    /// The runs of the cells `order` of `mesh`, in that order.
    fn of(mesh: &HighOrderMesh, order: Vec<u32>, n: usize) -> Self {
        // From the cell count alone, never the thread count: the runs fix the order of the
        // sums.
        let run_length = order
            .len()
            .div_ceil(MIN_RUNS)
            .clamp(MIN_CELLS_PER_RUN, CELLS_PER_RUN)
            .min(usize::from(u16::MAX) / n.max(1))
            .max(1);
        // Each run's distinct nodes (increasing) and its cells' nodes as positions in them;
        // the runs in parallel, concatenated in order.
        let per_run: Vec<(Vec<u32>, Vec<u16>)> = order
            .par_chunks(run_length)
            .map(|run| {
                let mut distinct = Vec::with_capacity(run.len() * n);
                for &c in run {
                    distinct.extend_from_slice(&mesh.cells[c as usize].nodes);
                }
                distinct.sort_unstable();
                distinct.dedup();
                let local = run
                    .iter()
                    .flat_map(|&c| &mesh.cells[c as usize].nodes)
                    .map(|v| distinct.partition_point(|w| w < v) as u16)
                    .collect();
                (distinct, local)
            })
            .collect();
        let mut run_start = Vec::with_capacity(per_run.len() + 1);
        run_start.push(0);
        let total: usize = per_run.iter().map(|(d, _)| d.len()).sum();
        let (mut run_nodes, mut local) = (
            Vec::with_capacity(total),
            Vec::with_capacity(order.len() * n),
        );
        for (distinct, cells) in &per_run {
            run_nodes.extend_from_slice(distinct);
            run_start.push(run_nodes.len());
            local.extend_from_slice(cells);
        }
        let (colours, sequential) = colour_runs(&run_start, &run_nodes, mesh.nodes.len());
        CellRuns {
            order,
            n,
            run_length,
            run_start,
            run_nodes,
            local,
            colours,
            sequential,
        }
    }

    /// The positions of run k's cells.
    pub fn cells_of_run(&self, k: usize) -> std::ops::Range<usize> {
        let start = k * self.run_length;
        start..(start + self.run_length).min(self.order.len())
    }

    /// Run k's distinct nodes, increasing.
    pub fn nodes_of_run(&self, k: usize) -> &[u32] {
        &self.run_nodes[self.run_range(k)]
    }

    /// Where run k's distinct nodes are in [`CellRuns::run_nodes`].
    pub fn run_range(&self, k: usize) -> std::ops::Range<usize> {
        self.run_start[k]..self.run_start[k + 1]
    }

    /// The distinct nodes of every run, run after run.
    pub fn run_nodes(&self) -> &[u32] {
        &self.run_nodes
    }

    /// The nodes of the cell at `position` as positions in its run's node list.
    pub fn local(&self, position: usize) -> &[u16] {
        &self.local[position * self.n..(position + 1) * self.n]
    }

    /// Calls `work(state, run)` on every run: colour after colour, the runs of a colour in
    /// parallel (each with a state from `init`), then the uncoloured runs in order.
    pub fn for_each_run<S>(
        &self,
        init: impl Fn() -> S + Sync + Send,
        work: impl Fn(&mut S, usize) + Sync + Send,
    ) {
        for class in &self.colours {
            class
                .par_iter()
                .for_each_init(&init, |state, &k| work(state, k as usize));
        }
        let mut state = init();
        for &k in &self.sequential {
            work(&mut state, k as usize);
        }
    }
}

/// The cells of `mesh` that `keep` keeps, sorted by the Morton code (bit-interleaved
/// coordinates, 21 bits per axis in the bounding box) of their first vertices' centroid,
/// ties by index.
fn morton_order(
    mesh: &HighOrderMesh,
    keep: impl Fn(&hocurve_mesh::HighOrderElement) -> bool + Sync,
) -> Vec<u32> {
    let nv = mesh.dim + 1;
    let (mut low, mut high) = ([f64::MAX; 3], [f64::MIN; 3]);
    for x in &mesh.nodes {
        for d in 0..3 {
            low[d] = low[d].min(x[d]);
            high[d] = high[d].max(x[d]);
        }
    }
    let spread: f64 = (0..3).map(|d| high[d] - low[d]).fold(0.0, f64::max);
    let top = ((1u64 << 21) - 1) as f64;
    let scale = if spread > 0.0 { top / spread } else { 0.0 };
    // Spreads the low 21 bits of v to every third bit.
    let spread_bits = |v: u64| {
        let mut v = v & 0x1f_ffff;
        v = (v | v << 32) & 0x1f_0000_0000_ffff;
        v = (v | v << 16) & 0x1f_0000_ff00_00ff;
        v = (v | v << 8) & 0x100f_00f0_0f00_f00f;
        v = (v | v << 4) & 0x10c3_0c30_c30c_30c3;
        (v | v << 2) & 0x1249_2492_4924_9249
    };
    let mut keyed: Vec<(u64, u32)> = mesh
        .cells
        .par_iter()
        .enumerate()
        .filter(|(_, cell)| keep(cell))
        .map(|(c, cell)| {
            let mut x = [0.0; 3];
            for &v in cell.nodes.iter().take(nv) {
                for d in 0..3 {
                    x[d] += mesh.nodes[v as usize][d] / nv as f64;
                }
            }
            let code = (0..3).fold(0u64, |code, d| {
                let q = ((x[d] - low[d]) * scale).clamp(0.0, top) as u64;
                code | spread_bits(q) << d
            });
            (code, c as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, c)| c).collect()
}

/// Greedy colouring of the runs (run k's distinct nodes at
/// `run_nodes[run_start[k]..run_start[k + 1]]`) so that runs of one colour share no node:
/// each run, in order, takes the colour with the fewest runs among the at most 64 not yet
/// used by a run touching one of its nodes (a bit mask per node), a new one only when all are
/// taken. Then runs move from one colour with an odd number of runs to another such, where
/// they fit, so that two threads share each colour evenly. Returns the runs of each colour
/// (increasing) and, in order, those that found all 64 colours taken.
///
/// The threads wait for each other at the end of every colour: with the lowest free colour
/// (the plain greedy rule) the 6 k sphere's 127 runs fell into 16 colours of 15 down to 2
/// runs, 9 of them odd, and two threads made a p = 4 mat-vec only 1.8× faster than one.
/// Balanced (15 colours of 8 to 10, one odd): f32 mat-vec 3.3 → 3.15 ms, the whole run
/// 0.455 → 0.426 s at p = 4 and 1.29 → 1.12 s at p = 5 (best of 7 and 3).
fn colour_runs(run_start: &[usize], run_nodes: &[u32], nodes: usize) -> (Vec<Vec<u32>>, Vec<u32>) {
    let mut used = vec![0u64; nodes];
    let mut colours: Vec<Vec<u32>> = Vec::new();
    let mut sequential = Vec::new();
    let run = |k: usize| &run_nodes[run_start[k]..run_start[k + 1]];
    let taken_by =
        |used: &[u64], k: usize| run(k).iter().fold(0u64, |mask, &v| mask | used[v as usize]);
    for k in 0..run_start.len().saturating_sub(1) {
        let taken = taken_by(&used, k);
        if taken == u64::MAX {
            sequential.push(k as u32);
            continue;
        }
        // The least used free colour (the lowest on ties), or a new one.
        let colour = (0..colours.len())
            .filter(|&c| taken & (1 << c) == 0)
            .min_by_key(|&c| colours[c].len())
            .unwrap_or(colours.len());
        if colour == colours.len() {
            colours.push(Vec::new());
        }
        colours[colour].push(k as u32);
        run(k).iter().for_each(|&v| used[v as usize] |= 1 << colour);
    }
    // Pair up the odd colours: a run of one (the last that fits) moves to the other. Its
    // nodes carry its own colour's bit only from itself (runs of a colour share no node).
    loop {
        let odd: Vec<usize> = (0..colours.len())
            .filter(|&c| colours[c].len() % 2 == 1)
            .collect();
        let moved = odd.iter().find_map(|&from| {
            colours[from].iter().rev().find_map(|&k| {
                let taken = taken_by(&used, k as usize);
                odd.iter()
                    .find(|&&to| to != from && taken & (1 << to) == 0)
                    .map(|&to| (k, from, to))
            })
        });
        let Some((k, from, to)) = moved else {
            break;
        };
        colours[from].retain(|&j| j != k);
        let at = colours[to].partition_point(|&j| j < k);
        colours[to].insert(at, k);
        run(k as usize).iter().for_each(|&v| {
            used[v as usize] = (used[v as usize] & !(1 << from)) | 1 << to;
        });
    }
    colours.retain(|c| !c.is_empty());
    (colours, sequential)
}

/// How a node enters the reduced unknowns.
const FREE: u32 = u32::MAX;
const FIXED: u32 = u32::MAX - 1;
/// A [`ReducedNodes::slot`]: the first reduced dof of a free node, SLIDING | the index of a
/// sliding node's frame, or FIXED_SLOT.
const SLIDING: u32 = 1 << 31;
const FIXED_SLOT: u32 = u32::MAX;

/// The reduced numbering of [`Constraints`] in compact form: per node its first reduced dof
/// and whether it is free, fixed or sliding (then its tangents).
pub(crate) struct ReducedNodes {
    pub dim: usize,
    /// First reduced dof of each node (`len = nodes + 1`).
    first: Vec<usize>,
    /// FREE, FIXED, or the index of a sliding node's tangents in `frames`.
    kind: Vec<u32>,
    frames: Vec<[[f64; 3]; 2]>,
    /// The first reduced dof of each sliding node, by frame.
    frame_first: Vec<usize>,
}

impl ReducedNodes {
    pub fn new(constraints: &Constraints) -> Self {
        let (mut frames, mut frame_first) = (Vec::new(), Vec::new());
        let kind = (0..constraints.count.len())
            .map(|node| {
                if constraints.count[node] == 0 {
                    FIXED
                } else if constraints.identity[node] {
                    FREE
                } else {
                    let q = &constraints.directions[node];
                    frames.push([q[0], q[1]]);
                    frame_first.push(constraints.first[node]);
                    (frames.len() - 1) as u32
                }
            })
            .collect();
        ReducedNodes {
            dim: constraints.dim,
            first: constraints.first.clone(),
            kind,
            frames,
            frame_first,
        }
    }

    /// Whether every node has a [`ReducedNodes::slot`] (fewer than 2³¹ unknowns and sliding
    /// nodes).
    pub fn slots_fit(&self) -> bool {
        self.len() < SLIDING as usize && self.frames.len() < SLIDING as usize
    }

    /// Node `node`'s reduced dofs in one word, to keep next to a run's nodes: a run's
    /// gathers then read one random place per node (its values) instead of three.
    pub fn slot(&self, node: usize) -> u32 {
        match self.kind[node] {
            FIXED => FIXED_SLOT,
            FREE => self.first[node] as u32,
            frame => SLIDING | frame,
        }
    }

    /// The first reduced dof of the node with `slot`, if it has any.
    #[inline(always)]
    pub fn first_of_slot(&self, slot: u32) -> Option<usize> {
        if slot == FIXED_SLOT {
            None
        } else if slot & SLIDING == 0 {
            Some(slot as usize)
        } else {
            Some(self.frame_first[(slot & !SLIDING) as usize])
        }
    }

    /// [`ReducedNodes::expand`] by slot.
    #[inline(always)]
    pub fn expand_slot(&self, slot: u32, y: &[f64]) -> [f64; 3] {
        let mut v = [0.0; 3];
        if slot == FIXED_SLOT {
        } else if slot & SLIDING == 0 {
            let f = slot as usize;
            (0..self.dim).for_each(|d| v[d] = y[f + d]);
        } else {
            let frame = (slot & !SLIDING) as usize;
            let (q, f) = (&self.frames[frame], self.frame_first[frame]);
            for (i, qi) in q.iter().enumerate().take(self.dim - 1) {
                for d in 0..self.dim {
                    v[d] += y[f + i] * qi[d];
                }
            }
        }
        v
    }

    /// [`ReducedNodes::restrict`] by slot.
    #[inline(always)]
    pub fn restrict_slot(&self, slot: u32, v: [f64; 3], add: impl Fn(usize, f64)) {
        if slot == FIXED_SLOT {
        } else if slot & SLIDING == 0 {
            let f = slot as usize;
            (0..self.dim).for_each(|d| add(f + d, v[d]));
        } else {
            let frame = (slot & !SLIDING) as usize;
            let (q, f) = (&self.frames[frame], self.frame_first[frame]);
            for (i, qi) in q.iter().enumerate().take(self.dim - 1) {
                add(f + i, (0..self.dim).map(|d| qi[d] * v[d]).sum());
            }
        }
    }

    /// Number of reduced unknowns.
    pub fn len(&self) -> usize {
        self.first.last().copied().unwrap_or(0)
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.kind.len()
    }

    /// First reduced dof of each node (`len = nodes + 1`).
    pub fn first(&self) -> &[usize] {
        &self.first
    }

    /// Whether `node` has no free direction.
    pub fn is_fixed(&self, node: usize) -> bool {
        self.kind[node] == FIXED
    }

    /// Node `node`'s displacement Q_nᵀ y_n from the reduced vector `y` (0 when fixed).
    #[inline]
    pub fn expand(&self, node: usize, y: &[f64]) -> [f64; 3] {
        let f = self.first[node];
        let mut v = [0.0; 3];
        match self.kind[node] {
            FIXED => {}
            // An element-wise copy: `copy_from_slice` of a run-time length calls memcpy.
            FREE => (0..self.dim).for_each(|d| v[d] = y[f + d]),
            frame => {
                let q = &self.frames[frame as usize];
                for (i, qi) in q.iter().enumerate().take(self.dim - 1) {
                    for d in 0..self.dim {
                        v[d] += y[f + i] * qi[d];
                    }
                }
            }
        }
        v
    }

    /// Adds Q_n v to node `node`'s reduced dofs through `add(dof, value)`.
    #[inline]
    pub fn restrict(&self, node: usize, v: [f64; 3], add: impl Fn(usize, f64)) {
        let f = self.first[node];
        match self.kind[node] {
            FIXED => {}
            FREE => (0..self.dim).for_each(|d| add(f + d, v[d])),
            frame => {
                let q = &self.frames[frame as usize];
                for (i, qi) in q.iter().enumerate().take(self.dim - 1) {
                    add(f + i, (0..self.dim).map(|d| qi[d] * v[d]).sum());
                }
            }
        }
    }

    /// The free directions of `node` and their number (0 when fixed).
    pub fn directions(&self, node: usize) -> ([[f64; 3]; 3], usize) {
        let mut q = [[0.0; 3]; 3];
        match self.kind[node] {
            FIXED => (q, 0),
            FREE => {
                (0..3).for_each(|d| q[d][d] = 1.0);
                (q, self.dim)
            }
            frame => {
                q[..2].copy_from_slice(&self.frames[frame as usize]);
                (q, self.dim - 1)
            }
        }
    }
}

/// A vector summed from contributions that threads add to disjoint entries at a time (runs
/// of one colour): atomics only make that sharing expressible without `unsafe`; plain loads
/// and stores suffice.
#[derive(Default)]
pub(crate) struct SharedSum(Mutex<Vec<AtomicU64>>);

impl SharedSum {
    /// y = the sum of what `fill(sums)` adds with [`Sums::add`].
    pub fn collect(&self, y: &mut [f64], fill: impl FnOnce(Sums)) {
        let mut sums = self
            .0
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        if sums.len() != y.len() {
            *sums = (0..y.len()).map(|_| AtomicU64::new(0)).collect();
        } else {
            sums.par_iter().for_each(|s| s.store(0, Ordering::Relaxed));
        }
        let sums = &*sums;
        fill(Sums(sums));
        y.par_iter_mut()
            .zip(sums.par_iter())
            .for_each(|(yi, s)| *yi = f64::from_bits(s.load(Ordering::Relaxed)));
    }
}

/// The entries of a [`SharedSum`] being summed.
#[derive(Clone, Copy)]
pub(crate) struct Sums<'a>(&'a [AtomicU64]);

impl Sums<'_> {
    /// Hints the CPU to fetch entry `i` (see [`prefetch`]).
    #[inline(always)]
    pub fn prefetch(&self, i: usize) {
        prefetch(self.0, i);
    }

    /// Adds `value` to entry `i`.
    #[inline]
    pub fn add(&self, i: usize, value: f64) {
        add_to(&self.0[i], value);
    }
}

/// Hints the CPU to fetch the cache line of `data[i]` (nothing if i is out of range or off
/// x86-64): the gathers and scatters of a run touch places scattered over vectors far larger
/// than the caches, and asking for them some nodes ahead hides part of the wait.
#[inline(always)]
pub(crate) fn prefetch<T>(data: &[T], i: usize) {
    #[cfg(target_arch = "x86_64")]
    if i < data.len() {
        // SAFETY: a prefetch is only a hint and never faults; the address lies in `data`.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            _mm_prefetch::<_MM_HINT_T0>(data.as_ptr().add(i).cast());
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (data, i);
}

/// Adds `value` to the f64 in `slot`, which no other thread touches meanwhile.
#[inline]
pub(crate) fn add_to(slot: &AtomicU64, value: f64) {
    let sum = f64::from_bits(slot.load(Ordering::Relaxed)) + value;
    slot.store(sum.to_bits(), Ordering::Relaxed);
}

#[cfg(test)]
#[path = "tests/cell_runs.rs"]
mod tests;
