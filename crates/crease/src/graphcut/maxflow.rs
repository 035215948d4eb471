//! Maximum flow / minimum s-t cut by the augmenting-path algorithm of Boykov and Kolmogorov:
//! Y. Boykov, V. Kolmogorov, "An experimental comparison of min-cut/max-flow algorithms for
//! energy minimization in vision", IEEE PAMI 26(9), 2004, section 3.
//!
//! **Algorithm.** Two search trees are kept: S grows from the source, T from the sink; every
//! node is in S, in T or free. A node of S is linked to its parent by a non-saturated arc
//! parent → node, a node of T by a non-saturated arc node → parent; the roots are linked to
//! their terminal by their residual terminal capacity. Three stages repeat (section 3.2):
//! 1. *growth*: active nodes (the trees' frontier, processed first-in first-out) acquire free
//!    neighbours through non-saturated arcs, until an arc links a node of S to a node of T —
//!    an augmenting path source → … → sink;
//! 2. *augmentation*: the path's bottleneck capacity is pushed; the arcs it saturates cut
//!    their child nodes off the trees (orphans);
//! 3. *adoption*: every orphan looks for a new parent in its own tree whose chain of parents
//!    reaches the terminal; an orphan that finds none becomes free and its children orphans.
//!
//! The algorithm ends when no active node remains: the trees then cannot grow, no augmenting
//! path exists and the flow is maximum. The source side of the minimum cut is S (plus the free
//! nodes, which reach neither terminal in the residual graph; the cut is minimum either way).
//!
//! Two refinements of Kolmogorov's implementation (maxflow v3, section 3.3 of the paper) are
//! used: a time stamp and a distance to the terminal per node, so an orphan prefers the parent
//! nearest to the terminal and the origin checks of one adoption stage share their work; and
//! during growth a node of the tree is re-parented to the growing node when that shortens its
//! path to the terminal.
//!
//! **Data layout.** Arcs are stored grouped by their tail (CSR, `offsets` per node), each with
//! its head, its reverse arc (`sister`) and its residual capacity; the terminal links are one
//! signed residual per node (`> 0`: source → node, `< 0`: node → sink), and a node's equal
//! parts of both terminal capacities are pushed at once ([`Graph::add_tweights`]). Nothing is
//! hashed and the processing order is fixed (node order, arc insertion order, FIFO queues), so
//! the result is deterministic.
//!
//! **Floating point.** Each augmentation subtracts the bottleneck from the arc that defines it,
//! which gives exactly zero, so every augmentation saturates at least one arc, as with integer
//! capacities. The flow value is a sum of f64 pushes: with integer-valued capacities below
//! 2^53 it is exact.

use std::collections::VecDeque;

use crate::{Error, Result};

/// `parent` value of a free node.
const NONE: u32 = u32::MAX;
/// `parent` value of a root, linked to its terminal.
const TERMINAL: u32 = u32::MAX - 1;
/// `parent` value of an orphan.
const ORPHAN: u32 = u32::MAX - 2;
/// Largest number of arcs (two per edge).
const MAX_ARCS: usize = (u32::MAX - 3) as usize;

/// A directed graph with two terminals (source and sink) and its maximum flow.
///
/// Build it with [`Graph::new`], [`Graph::add_edge`] and [`Graph::add_tweights`], then call
/// [`Graph::maxflow`] once and read the cut with [`Graph::is_source_side`]. Adding edges or
/// terminal capacities after [`Graph::maxflow`] is an error.
///
/// ```
/// use crease::graphcut::Graph;
/// let mut g = Graph::new(2);
/// g.add_tweights(0, 5.0, 1.0)?; // source → 0: 5, 0 → sink: 1
/// g.add_tweights(1, 2.0, 6.0)?;
/// g.add_edge(0, 1, 3.0, 4.0)?; // 0 → 1: 3, 1 → 0: 4
/// assert_eq!(g.maxflow(), 1.0 + 2.0 + 3.0);
/// assert!(g.is_source_side(0) && !g.is_source_side(1));
/// # Ok::<(), crease::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Graph {
    n: usize,
    /// Edges added so far: (a, b, cap a→b, cap b→a); moved into the arc arrays by `maxflow`.
    pending: Vec<(u32, u32, f64, f64)>,
    /// Residual terminal capacity: > 0 source → node, < 0 node → sink.
    tr_cap: Vec<f64>,
    /// Flow already pushed (the terminal capacities' common parts, then the augmentations).
    flow: f64,
    solved: bool,
    // Arc arrays (CSR by tail), filled by `maxflow`.
    offsets: Vec<u32>,
    head: Vec<u32>,
    sister: Vec<u32>,
    r_cap: Vec<f64>,
    // Search-tree state per node.
    parent: Vec<u32>,
    in_sink: Vec<bool>,
    active: Vec<bool>,
    ts: Vec<u32>,
    dist: Vec<u32>,
}

impl Graph {
    /// An empty graph on nodes `0..num_nodes` (no edges, no terminal links).
    pub fn new(num_nodes: usize) -> Self {
        Graph::with_capacity(num_nodes, 0)
    }

    /// [`Graph::new`] with room for `num_edges` calls of [`Graph::add_edge`].
    pub fn with_capacity(num_nodes: usize, num_edges: usize) -> Self {
        Graph {
            n: num_nodes,
            pending: Vec::with_capacity(num_edges),
            tr_cap: vec![0.0; num_nodes],
            flow: 0.0,
            solved: false,
            offsets: Vec::new(),
            head: Vec::new(),
            sister: Vec::new(),
            r_cap: Vec::new(),
            parent: Vec::new(),
            in_sink: Vec::new(),
            active: Vec::new(),
            ts: Vec::new(),
            dist: Vec::new(),
        }
    }

    /// Number of non-terminal nodes.
    pub fn num_nodes(&self) -> usize {
        self.n
    }

    /// Number of edges added (each is a pair of opposite arcs).
    pub fn num_edges(&self) -> usize {
        if self.solved {
            self.head.len() / 2
        } else {
            self.pending.len()
        }
    }

    fn check_open(&self, what: &str) -> Result<()> {
        if self.solved {
            return Err(Error::InvalidArgument(format!(
                "max-flow graph: {what} after maxflow()"
            )));
        }
        Ok(())
    }

    fn check_node(&self, i: usize) -> Result<()> {
        if i >= self.n {
            return Err(Error::InvalidArgument(format!(
                "max-flow graph: node {i} out of range (graph has {} nodes)",
                self.n
            )));
        }
        Ok(())
    }

    /// Adds the arcs a → b of capacity `cap_ab` and b → a of capacity `cap_ba`.
    ///
    /// Errors: a node out of range, a capacity negative or not finite, too many edges
    /// (more than 2^31 − 2), or the flow already computed. An edge from a node to itself is
    /// accepted and ignored (it never crosses a cut).
    pub fn add_edge(&mut self, a: usize, b: usize, cap_ab: f64, cap_ba: f64) -> Result<()> {
        self.check_open("add_edge")?;
        self.check_node(a)?;
        self.check_node(b)?;
        for c in [cap_ab, cap_ba] {
            if !(c.is_finite() && c >= 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "max-flow graph: capacity of edge ({a}, {b}) must be finite and >= 0, got {c}"
                )));
            }
        }
        if a == b {
            return Ok(());
        }
        if 2 * (self.pending.len() + 1) > MAX_ARCS {
            return Err(Error::InvalidArgument(format!(
                "max-flow graph: more than {} edges",
                MAX_ARCS / 2
            )));
        }
        self.pending.push((a as u32, b as u32, cap_ab, cap_ba));
        Ok(())
    }

    /// Adds `cap_source` to the capacity of source → `node` and `cap_sink` to that of
    /// `node` → sink. Calls accumulate.
    ///
    /// Errors: node out of range, a capacity negative or not finite, or the flow already
    /// computed.
    pub fn add_tweights(&mut self, node: usize, cap_source: f64, cap_sink: f64) -> Result<()> {
        self.check_open("add_tweights")?;
        self.check_node(node)?;
        for c in [cap_source, cap_sink] {
            if !(c.is_finite() && c >= 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "max-flow graph: terminal capacity of node {node} must be finite and >= 0, got {c}"
                )));
            }
        }
        // The common part min(cap_source, cap_sink) is a path source → node → sink: push it now.
        let t = &mut self.tr_cap[node];
        let (mut cs, mut ct) = (cap_source, cap_sink);
        if *t > 0.0 {
            cs += *t;
        } else {
            ct -= *t;
        }
        self.flow += cs.min(ct);
        *t = cs - ct;
        Ok(())
    }

    /// Computes the maximum flow from the source to the sink and returns its value (the
    /// capacity of the minimum cut). A second call returns the same value without work.
    pub fn maxflow(&mut self) -> f64 {
        if !self.solved {
            self.build();
            self.solved = true;
            self.run();
        }
        self.flow
    }

    /// Whether `node` is on the source side of the minimum cut found by [`Graph::maxflow`]
    /// (nodes that reach neither terminal in the residual graph are put on the source side).
    /// Before [`Graph::maxflow`], or for a node out of range, returns true.
    pub fn is_source_side(&self, node: usize) -> bool {
        match self.parent.get(node) {
            Some(&p) if p != NONE => !self.in_sink[node],
            _ => true,
        }
    }

    /// The source-side flags of all nodes (see [`Graph::is_source_side`]).
    pub fn source_side(&self) -> Vec<bool> {
        (0..self.n).map(|i| self.is_source_side(i)).collect()
    }

    /// Moves the pending edges into the CSR arc arrays (counting sort by tail).
    fn build(&mut self) {
        let n = self.n;
        let mut offsets = vec![0u32; n + 1];
        for &(a, b, _, _) in &self.pending {
            offsets[a as usize + 1] += 1;
            offsets[b as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let m = offsets[n] as usize;
        let mut next: Vec<u32> = offsets[..n].to_vec();
        let mut head = vec![0u32; m];
        let mut sister = vec![0u32; m];
        let mut r_cap = vec![0.0f64; m];
        for &(a, b, cab, cba) in &self.pending {
            let pa = next[a as usize];
            next[a as usize] += 1;
            let pb = next[b as usize];
            next[b as usize] += 1;
            head[pa as usize] = b;
            head[pb as usize] = a;
            sister[pa as usize] = pb;
            sister[pb as usize] = pa;
            r_cap[pa as usize] = cab;
            r_cap[pb as usize] = cba;
        }
        self.pending = Vec::new();
        self.offsets = offsets;
        self.head = head;
        self.sister = sister;
        self.r_cap = r_cap;
    }

    #[inline]
    fn arcs(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    fn run(&mut self) {
        let n = self.n;
        self.parent = vec![NONE; n];
        self.in_sink = vec![false; n];
        self.active = vec![false; n];
        self.ts = vec![0; n];
        self.dist = vec![0; n];
        let mut queue: VecDeque<u32> = VecDeque::new();
        let mut orphans: VecDeque<u32> = VecDeque::new();
        for i in 0..n {
            let t = self.tr_cap[i];
            if t != 0.0 {
                self.in_sink[i] = t < 0.0;
                self.parent[i] = TERMINAL;
                self.dist[i] = 1;
                self.active[i] = true;
                queue.push_back(i as u32);
            }
        }
        let mut time: u32 = 0;
        let mut current: Option<usize> = None;
        loop {
            // The node to grow from: the current one while it stays in a tree, else the next
            // active node.
            let mut node = current.take().filter(|&i| {
                self.active[i] = false;
                self.parent[i] != NONE
            });
            if node.is_none() {
                while let Some(i) = queue.pop_front() {
                    let i = i as usize;
                    self.active[i] = false;
                    if self.parent[i] != NONE {
                        node = Some(i);
                        break;
                    }
                }
            }
            let Some(i) = node else { break };

            // Growth.
            let mut bridge = None;
            if !self.in_sink[i] {
                for a in self.arcs(i) {
                    if self.r_cap[a] > 0.0 {
                        let j = self.head[a] as usize;
                        if self.parent[j] == NONE {
                            self.in_sink[j] = false;
                            self.parent[j] = self.sister[a];
                            self.ts[j] = self.ts[i];
                            self.dist[j] = self.dist[i] + 1;
                            make_active(&mut self.active, &mut queue, j);
                        } else if self.in_sink[j] {
                            bridge = Some(a);
                            break;
                        } else if self.ts[j] <= self.ts[i] && self.dist[j] > self.dist[i] {
                            self.parent[j] = self.sister[a];
                            self.ts[j] = self.ts[i];
                            self.dist[j] = self.dist[i] + 1;
                        }
                    }
                }
            } else {
                for a in self.arcs(i) {
                    let sa = self.sister[a] as usize;
                    if self.r_cap[sa] > 0.0 {
                        let j = self.head[a] as usize;
                        if self.parent[j] == NONE {
                            self.in_sink[j] = true;
                            self.parent[j] = sa as u32;
                            self.ts[j] = self.ts[i];
                            self.dist[j] = self.dist[i] + 1;
                            make_active(&mut self.active, &mut queue, j);
                        } else if !self.in_sink[j] {
                            bridge = Some(sa);
                            break;
                        } else if self.ts[j] <= self.ts[i] && self.dist[j] > self.dist[i] {
                            self.parent[j] = sa as u32;
                            self.ts[j] = self.ts[i];
                            self.dist[j] = self.dist[i] + 1;
                        }
                    }
                }
            }
            time = time.wrapping_add(1);
            if time == 0 {
                // After 2^32 augmentations the stamps would alias: reset them.
                self.ts.iter_mut().for_each(|t| *t = 0);
                time = 1;
            }
            let Some(bridge) = bridge else { continue };
            // i stays current (flagged active, not queued) and is grown again next round.
            self.active[i] = true;
            current = Some(i);
            self.augment(bridge, &mut orphans);
            // Adoption.
            while let Some(o) = orphans.pop_front() {
                if self.in_sink[o as usize] {
                    self.adopt_sink(o as usize, time, &mut queue, &mut orphans);
                } else {
                    self.adopt_source(o as usize, time, &mut queue, &mut orphans);
                }
            }
        }
    }

    /// Pushes the bottleneck along source → … → tail(bridge) → head(bridge) → … → sink.
    fn augment(&mut self, bridge: usize, orphans: &mut VecDeque<u32>) {
        let tail = self.head[self.sister[bridge] as usize] as usize;
        let headn = self.head[bridge] as usize;
        // Bottleneck.
        let mut b = self.r_cap[bridge];
        let mut i = tail;
        loop {
            let a = self.parent[i];
            if a == TERMINAL {
                b = b.min(self.tr_cap[i]);
                break;
            }
            b = b.min(self.r_cap[self.sister[a as usize] as usize]);
            i = self.head[a as usize] as usize;
        }
        let mut i = headn;
        loop {
            let a = self.parent[i];
            if a == TERMINAL {
                b = b.min(-self.tr_cap[i]);
                break;
            }
            b = b.min(self.r_cap[a as usize]);
            i = self.head[a as usize] as usize;
        }
        // Push.
        self.r_cap[self.sister[bridge] as usize] += b;
        self.r_cap[bridge] -= b;
        let mut i = tail;
        loop {
            let a = self.parent[i];
            if a == TERMINAL {
                self.tr_cap[i] -= b;
                if self.tr_cap[i] <= 0.0 {
                    self.tr_cap[i] = 0.0;
                    self.parent[i] = ORPHAN;
                    orphans.push_front(i as u32);
                }
                break;
            }
            let a = a as usize;
            let sa = self.sister[a] as usize;
            self.r_cap[a] += b;
            self.r_cap[sa] -= b;
            let next = self.head[a] as usize;
            if self.r_cap[sa] <= 0.0 {
                self.r_cap[sa] = 0.0;
                self.parent[i] = ORPHAN;
                orphans.push_front(i as u32);
            }
            i = next;
        }
        let mut i = headn;
        loop {
            let a = self.parent[i];
            if a == TERMINAL {
                self.tr_cap[i] += b;
                if self.tr_cap[i] >= 0.0 {
                    self.tr_cap[i] = 0.0;
                    self.parent[i] = ORPHAN;
                    orphans.push_front(i as u32);
                }
                break;
            }
            let a = a as usize;
            let sa = self.sister[a] as usize;
            self.r_cap[sa] += b;
            self.r_cap[a] -= b;
            let next = self.head[a] as usize;
            if self.r_cap[a] <= 0.0 {
                self.r_cap[a] = 0.0;
                self.parent[i] = ORPHAN;
                orphans.push_front(i as u32);
            }
            i = next;
        }
        self.flow += b;
    }

    /// Distance from `j` (in a tree, not an orphan itself unless invalid) to its terminal
    /// through its parents, or `None` when the chain reaches an orphan. Marks the visited
    /// chain with `time` and the distances.
    fn origin_dist(&mut self, j: usize, time: u32) -> Option<u32> {
        let mut d: u32 = 0;
        let mut k = j;
        loop {
            if self.ts[k] == time {
                d += self.dist[k];
                break;
            }
            let a = self.parent[k];
            d += 1;
            if a == TERMINAL {
                self.ts[k] = time;
                self.dist[k] = 1;
                break;
            }
            if a == ORPHAN || a == NONE {
                return None;
            }
            k = self.head[a as usize] as usize;
        }
        // Mark the chain so later checks in this adoption stage stop early.
        let mut k = j;
        let mut dd = d;
        while self.ts[k] != time {
            self.ts[k] = time;
            self.dist[k] = dd;
            dd = dd.saturating_sub(1);
            k = self.head[self.parent[k] as usize] as usize;
        }
        Some(d)
    }

    fn adopt_source(
        &mut self,
        i: usize,
        time: u32,
        queue: &mut VecDeque<u32>,
        orphans: &mut VecDeque<u32>,
    ) {
        let mut best: Option<(usize, u32)> = None;
        for a0 in self.arcs(i) {
            if self.r_cap[self.sister[a0] as usize] > 0.0 {
                let j = self.head[a0] as usize;
                if !self.in_sink[j] && self.parent[j] != NONE {
                    if let Some(d) = self.origin_dist(j, time) {
                        if best.is_none_or(|(_, bd)| d < bd) {
                            best = Some((a0, d));
                        }
                    }
                }
            }
        }
        self.finish_adoption(i, best, time, queue, orphans, false);
    }

    fn adopt_sink(
        &mut self,
        i: usize,
        time: u32,
        queue: &mut VecDeque<u32>,
        orphans: &mut VecDeque<u32>,
    ) {
        let mut best: Option<(usize, u32)> = None;
        for a0 in self.arcs(i) {
            if self.r_cap[a0] > 0.0 {
                let j = self.head[a0] as usize;
                if self.in_sink[j] && self.parent[j] != NONE {
                    if let Some(d) = self.origin_dist(j, time) {
                        if best.is_none_or(|(_, bd)| d < bd) {
                            best = Some((a0, d));
                        }
                    }
                }
            }
        }
        self.finish_adoption(i, best, time, queue, orphans, true);
    }

    fn finish_adoption(
        &mut self,
        i: usize,
        best: Option<(usize, u32)>,
        time: u32,
        queue: &mut VecDeque<u32>,
        orphans: &mut VecDeque<u32>,
        sink: bool,
    ) {
        if let Some((a0, d)) = best {
            self.parent[i] = a0 as u32;
            self.ts[i] = time;
            self.dist[i] = d + 1;
            return;
        }
        // No valid parent: i becomes free; its neighbours in the tree that could grow into
        // it become active, its children become orphans.
        self.parent[i] = NONE;
        for a0 in self.arcs(i) {
            let j = self.head[a0] as usize;
            let pj = self.parent[j];
            if self.in_sink[j] != sink || pj == NONE {
                continue;
            }
            let can_grow = if sink {
                self.r_cap[a0] > 0.0
            } else {
                self.r_cap[self.sister[a0] as usize] > 0.0
            };
            if can_grow {
                make_active(&mut self.active, queue, j);
            }
            if pj != TERMINAL && pj != ORPHAN && self.head[pj as usize] as usize == i {
                self.parent[j] = ORPHAN;
                orphans.push_back(j as u32);
            }
        }
    }
}

#[inline]
fn make_active(active: &mut [bool], queue: &mut VecDeque<u32>, j: usize) {
    if !active[j] {
        active[j] = true;
        queue.push_back(j as u32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use petgraph::algo::dinics;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// Capacity of the cut (source side from `g`) in the original network.
    fn cut_capacity(
        g: &Graph,
        edges: &[(usize, usize, u64, u64)],
        terms: &[(usize, u64, u64)],
    ) -> u64 {
        let mut c = 0;
        for &(a, b, cab, cba) in edges {
            let (sa, sb) = (g.is_source_side(a), g.is_source_side(b));
            if sa && !sb {
                c += cab;
            }
            if sb && !sa {
                c += cba;
            }
        }
        for &(i, cs, ct) in terms {
            c += if g.is_source_side(i) { ct } else { cs };
        }
        c
    }

    fn petgraph_flow(
        n: usize,
        edges: &[(usize, usize, u64, u64)],
        terms: &[(usize, u64, u64)],
    ) -> u64 {
        let mut pg = petgraph::Graph::<(), u64>::new();
        let nodes: Vec<_> = (0..n + 2).map(|_| pg.add_node(())).collect();
        let (s, t) = (nodes[n], nodes[n + 1]);
        for &(a, b, cab, cba) in edges {
            pg.add_edge(nodes[a], nodes[b], cab);
            pg.add_edge(nodes[b], nodes[a], cba);
        }
        for &(i, cs, ct) in terms {
            pg.add_edge(s, nodes[i], cs);
            pg.add_edge(nodes[i], t, ct);
        }
        dinics(&pg, s, t).0
    }

    #[test]
    fn random_graphs_match_petgraph_dinics() {
        let mut rng = Pcg64::seed_from_u64(7);
        for case in 0..400 {
            let n = rng.random_range(1..=24usize);
            let m = rng.random_range(0..=4 * n);
            let maxc = if case % 3 == 0 { 3 } else { 100 };
            let edges: Vec<(usize, usize, u64, u64)> = (0..m)
                .map(|_| {
                    let a = rng.random_range(0..n);
                    let b = rng.random_range(0..n);
                    // Zero capacities and one-way arcs are frequent.
                    let cab = rng.random_range(0..=maxc) * rng.random_range(0..2u64);
                    let cba = rng.random_range(0..=maxc) * rng.random_range(0..2u64);
                    (a, b, cab, cba)
                })
                .filter(|&(a, b, _, _)| a != b)
                .collect();
            let terms: Vec<(usize, u64, u64)> = (0..rng.random_range(0..=2 * n))
                .map(|_| {
                    (
                        rng.random_range(0..n),
                        rng.random_range(0..=maxc) * rng.random_range(0..2u64),
                        rng.random_range(0..=maxc) * rng.random_range(0..2u64),
                    )
                })
                .collect();
            let mut g = Graph::new(n);
            for &(a, b, cab, cba) in &edges {
                g.add_edge(a, b, cab as f64, cba as f64).unwrap();
            }
            for &(i, cs, ct) in &terms {
                g.add_tweights(i, cs as f64, ct as f64).unwrap();
            }
            let f = g.maxflow();
            let expected = petgraph_flow(n, &edges, &terms);
            assert_eq!(f, expected as f64, "case {case}: n={n} m={}", edges.len());
            assert_eq!(
                cut_capacity(&g, &edges, &terms),
                expected,
                "case {case}: the cut is not minimum"
            );
        }
    }

    #[test]
    fn real_capacities_match_petgraph() {
        let mut rng = Pcg64::seed_from_u64(11);
        for case in 0..100 {
            let n = rng.random_range(2..=30usize);
            let mut g = Graph::new(n);
            let mut pg = petgraph::Graph::<(), f64>::new();
            let nodes: Vec<_> = (0..n + 2).map(|_| pg.add_node(())).collect();
            let mut orig = Vec::new();
            for _ in 0..3 * n {
                let (a, b) = (rng.random_range(0..n), rng.random_range(0..n));
                if a == b {
                    continue;
                }
                let (x, y) = (rng.random::<f64>(), rng.random::<f64>());
                g.add_edge(a, b, x, y).unwrap();
                pg.add_edge(nodes[a], nodes[b], x);
                pg.add_edge(nodes[b], nodes[a], y);
                orig.push((a, b, x, y));
            }
            let mut tw = vec![(0.0, 0.0); n];
            for (i, t) in tw.iter_mut().enumerate() {
                let (x, y) = (rng.random::<f64>(), rng.random::<f64>());
                g.add_tweights(i, x, y).unwrap();
                pg.add_edge(nodes[n], nodes[i], x);
                pg.add_edge(nodes[i], nodes[n + 1], y);
                *t = (x, y);
            }
            let f = g.maxflow();
            let (e, _) = dinics(&pg, nodes[n], nodes[n + 1]);
            assert!((f - e).abs() < 1e-9, "case {case}: {f} vs {e}");
            let mut cut = 0.0;
            for &(a, b, x, y) in &orig {
                match (g.is_source_side(a), g.is_source_side(b)) {
                    (true, false) => cut += x,
                    (false, true) => cut += y,
                    _ => {}
                }
            }
            for (i, &(x, y)) in tw.iter().enumerate() {
                cut += if g.is_source_side(i) { y } else { x };
            }
            assert!((cut - f).abs() < 1e-9, "case {case}: cut {cut} flow {f}");
        }
    }

    #[test]
    fn hand_cases() {
        // Empty graph, no terminal links.
        let mut g = Graph::new(0);
        assert_eq!(g.maxflow(), 0.0);
        // A node with both terminal capacities: min of the two flows straight through.
        let mut g = Graph::new(1);
        g.add_tweights(0, 3.0, 5.0).unwrap();
        assert_eq!(g.maxflow(), 3.0);
        assert!(!g.is_source_side(0)); // the remaining 2 to the sink keeps it in T
        let mut g = Graph::new(1);
        g.add_tweights(0, 3.0, 1.0).unwrap();
        g.add_tweights(0, 1.0, 1.0).unwrap(); // accumulates: 4 and 2
        assert_eq!(g.maxflow(), 2.0);
        assert!(g.is_source_side(0));
        // Chain s → 0 → 1 → 2 → t with a bottleneck in the middle.
        let mut g = Graph::new(3);
        g.add_tweights(0, 10.0, 0.0).unwrap();
        g.add_tweights(2, 0.0, 10.0).unwrap();
        g.add_edge(0, 1, 7.0, 0.0).unwrap();
        g.add_edge(1, 2, 4.0, 100.0).unwrap();
        assert_eq!(g.maxflow(), 4.0);
        assert_eq!(g.source_side(), vec![true, true, false]);
        // Zero capacities: nothing flows, everything on the source side.
        let mut g = Graph::new(3);
        g.add_tweights(0, 0.0, 0.0).unwrap();
        g.add_edge(0, 1, 0.0, 0.0).unwrap();
        g.add_edge(1, 2, 0.0, 0.0).unwrap();
        assert_eq!(g.maxflow(), 0.0);
        assert_eq!(g.source_side(), vec![true; 3]);
        // Two components: the first carries 2, the second 5; a node linked to nothing.
        let mut g = Graph::new(5);
        g.add_tweights(0, 2.0, 0.0).unwrap();
        g.add_tweights(1, 0.0, 9.0).unwrap();
        g.add_edge(0, 1, 6.0, 0.0).unwrap();
        g.add_tweights(2, 8.0, 0.0).unwrap();
        g.add_tweights(3, 0.0, 5.0).unwrap();
        g.add_edge(2, 3, 9.0, 0.0).unwrap();
        assert_eq!(g.maxflow(), 7.0);
        // After the flow, 0 still reaches the sink (0 → 1 → t) and 3 is still reached from
        // the source (s → 2 → 3): the cut is the one nearest to each saturated terminal link.
        assert_eq!(g.source_side(), vec![false, false, true, true, true]);
        // Errors.
        let mut g = Graph::new(2);
        assert!(g.add_edge(0, 2, 1.0, 1.0).is_err());
        assert!(g.add_edge(0, 1, -1.0, 1.0).is_err());
        assert!(g.add_edge(0, 1, f64::NAN, 1.0).is_err());
        assert!(g.add_tweights(2, 1.0, 1.0).is_err());
        assert!(g.add_tweights(1, f64::INFINITY, 1.0).is_err());
        assert_eq!(g.maxflow(), 0.0);
        assert!(g.add_edge(0, 1, 1.0, 1.0).is_err());
        assert!(g.add_tweights(0, 1.0, 1.0).is_err());
    }

    #[test]
    fn grid_segmentation() {
        // A 40 × 40 image: a bright disc on a dark background, 15 % of the pixels flipped;
        // unaries from the intensity, 4-connected Potts smoothing recovers the disc.
        let (w, h) = (40usize, 40usize);
        let mut rng = Pcg64::seed_from_u64(3);
        let inside = |x: usize, y: usize| {
            let (dx, dy) = (x as f64 - 19.5, y as f64 - 19.5);
            dx * dx + dy * dy < 12.0 * 12.0
        };
        let lambda = 0.9;
        let mut g = Graph::new(w * h);
        let mut value = vec![0.0; w * h];
        let mut edges = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let mut v = if inside(x, y) { 1.0 } else { 0.0 };
                if rng.random::<f64>() < 0.15 {
                    v = 1.0 - v;
                }
                value[y * w + x] = v;
                // Label "object" = source side: cost of background 2v, of object 2(1 − v).
                g.add_tweights(y * w + x, 2.0 * v, 2.0 * (1.0 - v)).unwrap();
                if x + 1 < w {
                    edges.push((y * w + x, y * w + x + 1));
                }
                if y + 1 < h {
                    edges.push((y * w + x, (y + 1) * w + x));
                }
            }
        }
        for &(a, b) in &edges {
            g.add_edge(a, b, lambda, lambda).unwrap();
        }
        let flow = g.maxflow();
        let energy = |obj: &dyn Fn(usize) -> bool| {
            let d: f64 = (0..w * h)
                .map(|i| 2.0 * if obj(i) { 1.0 - value[i] } else { value[i] })
                .sum();
            let p = edges.iter().filter(|&&(a, b)| obj(a) != obj(b)).count() as f64;
            d + lambda * p
        };
        let cut = energy(&|i| g.is_source_side(i));
        let truth = energy(&|i| inside(i % w, i / w));
        let noisy = energy(&|i| value[i] == 1.0);
        assert!((cut - flow).abs() < 1e-9, "cut {cut} flow {flow}");
        assert!(cut <= truth && cut <= noisy, "{cut} {truth} {noisy}");
        let wrong = |obj: &dyn Fn(usize) -> bool| {
            (0..w * h)
                .filter(|&i| obj(i) != inside(i % w, i / w))
                .count()
        };
        let (before, after) = (wrong(&|i| value[i] == 1.0), wrong(&|i| g.is_source_side(i)));
        assert!(before > 200, "{before}");
        assert!(
            4 * after < before,
            "{after} pixels wrong after smoothing, {before} before"
        );
    }
}
