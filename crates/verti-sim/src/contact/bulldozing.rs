//! SCM's bulldozing: the soil a wheel presses down does not vanish. Each step the volume the
//! wheel's patch displaced (the growth of its nodes' plastic sinkage) is heaped onto the
//! patch's rim, the soil nodes next to it that carry no pressure, and then eroded: passes over
//! the rim and the rings of such nodes around it let heaped soil that the wheel holds down
//! flow on to the neighbours, and any step between free neighbours steeper than 55° slide.
//! Verti-Bench turns this on for every soil (`SetBulldozingParameters(55, 1, 5, 10)`), and it
//! is much of why its wheels ride high: the rim ahead of a rolling wheel rises before the
//! wheel reaches it, so the wheel meets soil sooner. Chrono's single HMMWV wheel at 3 m/s sinks
//! 0.124 m in snow with bulldozing and 0.158 m without; in mud 0.043 against 0.059 m.
//!
//! This follows `SCMLoader::ComputeInternalForces` of Chrono 9.0.1 step by step, with its
//! quirk (a node with remainder to spare pays out of it and loses as much level too), on a
//! window of nodes around one wheel's patch. Where it departs, each measured on the single
//! wheel and on the HMMWV on flat snow and mud and across a 15° slope of them: Chrono heaps
//! after every patch of a step, visiting nodes in hash order, and verti after each wheel, in
//! a fixed order; Chrono's erosion reaches 10 rings of nodes around the rim, verti's
//! [`EROSION_RINGS`] (1, 2 and 10 rings give the same sinkage on the flat to 0.1 mm and across
//! the slope to 2 mm and 0.1° of roll: the soil settles next to the rim); and two neighbours
//! of undeformed ground never erode (Chrono would level an undeformed slope steeper than 55°
//! next to a wheel). Nodes on rigid patches take no soil.

use crate::soil::{SoilLayout, SoilState};
use crate::terrain::{Ground, Terrain};
use std::cell::RefCell;
use std::ops::Range;
use verti_world::Surface;

/// Erosion angle: free neighbours may differ by δ·tan(55°) before soil slides.
const EROSION_ANGLE_DEG: f64 = 55.0;
/// Share of the displaced volume that is heaped (SCM's flow factor).
const FLOW_FACTOR: f64 = 1.0;
/// Erosion passes per step.
const EROSION_ITERATIONS: u8 = 5;
/// Rings of free nodes around the rim that the erosion reaches (Chrono: 10; the module docs
/// say why fewer give the same result).
pub(crate) const EROSION_RINGS: i64 = 2;

/// One node of a wheel's patch this step, as the contact stage saw it: the node's ray met the
/// wheel no higher than SCM's ray reach above the soil.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PatchNode {
    pub i: i64,
    pub j: i64,
    /// SCM's σ of the node this step, damping included (zero where the wheel is above it).
    pub sigma: f64,
    /// Growth of the node's plastic sinkage this step \[m\].
    pub flow: f64,
    /// Height of the wheel's lowest point over the node \[m\].
    pub hit: f64,
}

/// A node that carries no pressure (σ = 0): it takes heaped soil and slides.
const FREE: u8 = 0;
/// σ > 0: part of the patch.
const PRESSED: u8 = 1;
/// σ < 0 (the tread lifting off pulls): on the rim, but nothing slides onto it.
const PULLED: u8 = 2;
/// Off the grid or on a rigid patch.
const NO_SOIL: u8 = 3;

/// One node of the window.
#[derive(Clone, Copy)]
struct Node {
    /// Undeformed height \[m\], NaN until first needed.
    ground: f64,
    /// Soil heaped on the node: its undeformed level rose by this much \[m\].
    heap: f64,
    /// Soil waiting to flow on to the neighbours \[m\].
    remainder: f64,
    /// Plastic sinkage as a drop in height (sinkage / cos of the slope) \[m\].
    sunk: f64,
    /// Height of the wheel's lowest point above the node, if its ray met the wheel \[m\].
    hit: f64,
    at: (usize, usize),
    kind: u8,
    in_domain: bool,
    changed: bool,
    /// The erosion pass (1-based) in which the node last moved, and last got queued.
    moved_in: u8,
    queued: u8,
}

const BLANK: Node = Node {
    ground: f64::NAN,
    heap: 0.0,
    remainder: 0.0,
    sunk: 0.0,
    hit: f64::INFINITY,
    at: (0, 0),
    kind: NO_SOIL,
    in_domain: false,
    changed: false,
    moved_in: 0,
    queued: 0,
};

/// Scratch space for one window, reused across calls (no allocation per step).
#[derive(Default)]
struct Window {
    /// Width and height in nodes, the node indices of the first node and the node spacing.
    w: usize,
    h: usize,
    i0: i64,
    j0: i64,
    delta: f64,
    nodes: Vec<Node>,
    rim: Vec<usize>,
    domain: Vec<usize>,
    front: Vec<usize>,
    next: Vec<usize>,
    moved: Vec<usize>,
}

thread_local! {
    static WINDOW: RefCell<Window> = RefCell::new(Window::default());
}

impl Window {
    fn reset(&mut self, (i0, j0): (i64, i64), w: usize, h: usize, delta: f64) {
        (self.i0, self.j0, self.w, self.h, self.delta) = (i0, j0, w, h, delta);
        self.nodes.clear();
        self.nodes.resize(w * h, BLANK);
        for v in [
            &mut self.rim,
            &mut self.domain,
            &mut self.front,
            &mut self.next,
            &mut self.moved,
        ] {
            v.clear();
        }
    }

    /// The window index of node (i, j), if inside.
    #[inline]
    fn index(&self, i: i64, j: i64) -> Option<usize> {
        let (c, r) = (i - self.i0, j - self.j0);
        (c >= 0 && r >= 0 && (c as usize) < self.w && (r as usize) < self.h)
            .then(|| r as usize * self.w + c as usize)
    }

    /// The 4 neighbours of node `k` in SCM's order (south, west, east, north).
    #[inline]
    fn neighbours(&self, k: usize) -> [Option<usize>; 4] {
        let (r, c) = (k / self.w, k % self.w);
        [
            (r > 0).then(|| k - self.w),
            (c > 0).then(|| k - 1),
            (c + 1 < self.w).then(|| k + 1),
            (r + 1 < self.h).then(|| k + self.w),
        ]
    }

    /// Current height of node `k`'s soil \[m\].
    #[inline]
    fn level(&mut self, k: usize, ground: &Ground) -> f64 {
        let n = &mut self.nodes[k];
        if n.ground.is_nan() {
            let (c, r) = ((k % self.w) as i64, (k / self.w) as i64);
            let (x, y) = (
                (self.i0 + c) as f64 * self.delta,
                (self.j0 + r) as f64 * self.delta,
            );
            n.ground = ground.sample(x, y).0;
        }
        n.ground + n.heap - n.sunk
    }

    /// Takes node `k` into the erosion domain if it is soil carrying no pressure and not in it
    /// yet; true when taken.
    #[inline]
    fn claim(&mut self, k: usize) -> bool {
        let n = &mut self.nodes[k];
        let take = (n.kind == FREE || n.kind == PULLED) && !n.in_domain;
        n.in_domain |= take;
        take
    }

    #[inline]
    fn undeformed(&self, k: usize) -> bool {
        let n = &self.nodes[k];
        n.heap == 0.0 && n.remainder == 0.0 && n.sunk == 0.0
    }

    /// Soil added to node `k`; it cannot rise through the wheel above it, and what does not
    /// fit waits as remainder.
    #[inline]
    fn add(&mut self, amount: f64, k: usize, pass: u8, ground: &Ground) {
        let mut amount = amount;
        if self.nodes[k].hit.is_finite() {
            let room = (self.nodes[k].hit - self.level(k, ground)).max(0.0);
            if amount > room {
                self.nodes[k].remainder += amount - room;
                amount = room;
            }
        }
        self.nodes[k].heap += amount;
        self.note_change(k, pass);
    }

    /// Soil taken from node `k`, SCM's way: a node with remainder to spare pays out of it,
    /// and (as in Chrono) its level drops by the same amount too.
    #[inline]
    fn remove(&mut self, amount: f64, k: usize, pass: u8) {
        let mut amount = amount;
        let n = &mut self.nodes[k];
        if n.remainder > amount {
            n.remainder -= amount;
        } else if n.remainder < amount && n.remainder > 0.0 {
            amount -= n.remainder;
            n.remainder = 0.0;
        }
        n.heap -= amount;
        self.note_change(k, pass);
    }

    /// Marks node `k` changed (to be written back) and moved in erosion pass `pass`.
    #[inline]
    fn note_change(&mut self, k: usize, pass: u8) {
        let n = &mut self.nodes[k];
        n.changed = true;
        if pass > 0 && n.moved_in != pass {
            n.moved_in = pass;
            self.moved.push(k);
        }
    }
}

/// Heaps and erodes the soil one wheel displaced this step. `all[own]`: the wheel's patch
/// nodes; `all[others]`: the other wheels' this step, whose pressed nodes take no soil (a node
/// under any wheel is part of SCM's patches, never of a rim).
pub(crate) fn bulldoze(
    terrain: &Terrain,
    layout: &SoilLayout,
    state: &mut SoilState,
    all: &[PatchNode],
    own: Range<usize>,
    others: [Range<usize>; 2],
) {
    let nodes = &all[own];
    // the pressed nodes, their rim, the rings and the rings' neighbours
    let Some((i0, i1, j0, j1)) = nodes.iter().filter(|p| p.sigma > 0.0).fold(None, |b, p| {
        let (a, b, c, d) = b.unwrap_or((p.i, p.i, p.j, p.j));
        Some((a.min(p.i), b.max(p.i), c.min(p.j), d.max(p.j)))
    }) else {
        return;
    };
    WINDOW.with_borrow_mut(|win| {
        let pad = EROSION_RINGS + 2;
        let w = (i1 - i0 + 1 + 2 * pad) as usize;
        let h = (j1 - j0 + 1 + 2 * pad) as usize;
        win.reset((i0 - pad, j0 - pad), w, h, layout.delta);
        load(win, terrain, layout, state, nodes);
        for p in others.iter().flat_map(|r| &all[r.clone()]) {
            if p.sigma > 0.0
                && let Some(k) = win.index(p.i, p.j)
                && win.nodes[k].kind != NO_SOIL
            {
                win.nodes[k].kind = PRESSED;
                win.nodes[k].hit = p.hit;
            }
        }
        if heap_on_rim(win, nodes, &terrain.ground) {
            erode(win, &terrain.ground);
        }
        for n in &win.nodes {
            if n.changed {
                state.set_heap(n.at, n.heap, n.remainder);
            }
        }
    });
}

/// Reads the window's soil and the patch into `win`.
fn load(
    win: &mut Window,
    terrain: &Terrain,
    layout: &SoilLayout,
    state: &SoilState,
    nodes: &[PatchNode],
) {
    let patches = terrain.world.patches.patches();
    let is_soil = |x: f64, y: f64| {
        matches!(
            patches[terrain.ground.patch_index(x, y)].surface,
            Surface::Deformable { .. }
        )
    };
    let delta = win.delta;
    // patches are metres wide: a window inside one soil patch needs no check per node
    let (x0, y0) = (win.i0 as f64 * delta, win.j0 as f64 * delta);
    let (x1, y1) = (
        x0 + (win.w - 1) as f64 * delta,
        y0 + (win.h - 1) as f64 * delta,
    );
    let first = terrain.ground.patch_index(x0, y0);
    let one_patch = [(x1, y0), (x0, y1), (x1, y1)]
        .iter()
        .all(|&(x, y)| terrain.ground.patch_index(x, y) == first)
        && is_soil(x0, y0);
    for r in 0..win.h {
        let j = win.j0 + r as i64;
        let y = j as f64 * delta;
        let mut row = None;
        for c in 0..win.w {
            let i = win.i0 + c as i64;
            let Some(at) = layout.locate(i, j) else {
                continue;
            };
            let x = i as f64 * delta;
            if !one_patch && !is_soil(x, y) {
                continue;
            }
            let n = &mut win.nodes[r * win.w + c];
            n.kind = FREE;
            n.at = at;
            let node = state.node(at);
            (n.heap, n.remainder) = (node.heap, node.remainder);
            let plastic = node.plastic;
            if plastic != 0.0 {
                let (z, gx, gy) = row.get_or_insert_with(|| terrain.ground.row(y)).sample(x);
                n.ground = z;
                n.sunk = plastic * (1.0 + gx * gx + gy * gy).sqrt();
            }
        }
    }
    for p in nodes {
        let Some(k) = win.index(p.i, p.j) else {
            continue;
        };
        let n = &mut win.nodes[k];
        if n.kind == NO_SOIL {
            continue;
        }
        n.hit = p.hit;
        if p.sigma > 0.0 {
            n.kind = PRESSED;
        } else if p.sigma < 0.0 {
            n.kind = PULLED;
        }
    }
}

/// (1) The rim, the soil nodes next to the pressed ones that carry none, shares the volume
/// the pressed nodes displaced; then (2) the erosion domain, the rim and rings of such nodes
/// around it. False when there is no rim (nothing to erode).
fn heap_on_rim(win: &mut Window, nodes: &[PatchNode], ground: &Ground) -> bool {
    let mut displaced = 0.0;
    // (the wheel's own pressed nodes: another wheel's are PRESSED too, and a node this wheel
    // only touches may be one of them)
    for p in nodes.iter().filter(|p| p.sigma > 0.0) {
        let Some(k) = win
            .index(p.i, p.j)
            .filter(|&k| win.nodes[k].kind == PRESSED)
        else {
            continue;
        };
        displaced += p.flow;
        for nb in win.neighbours(k).into_iter().flatten() {
            if win.claim(nb) {
                win.rim.push(nb);
            }
        }
    }
    if win.rim.is_empty() {
        return false;
    }
    let each = FLOW_FACTOR * displaced / win.rim.len() as f64;
    for n in 0..win.rim.len() {
        let k = win.rim[n];
        win.add(each, k, 0, ground);
    }
    win.domain.extend_from_slice(&win.rim);
    std::mem::swap(&mut win.front, &mut win.rim);
    for _ in 0..EROSION_RINGS {
        win.next.clear();
        for n in 0..win.front.len() {
            let k = win.front[n];
            for nb in win.neighbours(k).into_iter().flatten() {
                if win.claim(nb) {
                    win.next.push(nb);
                }
            }
        }
        win.domain.extend_from_slice(&win.next);
        std::mem::swap(&mut win.front, &mut win.next);
    }
    true
}

/// (3) Erosion over the domain: remainders spread to neighbours with less, and steps between
/// free neighbours steeper than the erosion angle slide. A pass visits only the domain nodes
/// at or next to a node that moved in the pass before (the first pass visits them all): a
/// pair of nodes that did nothing and has not changed since would do nothing again, so this
/// gives what SCM's full passes give.
fn erode(win: &mut Window, ground: &Ground) {
    let limit = win.delta * EROSION_ANGLE_DEG.to_radians().tan();
    let w = win.w;
    std::mem::swap(&mut win.front, &mut win.domain);
    for pass in 1..=EROSION_ITERATIONS {
        win.moved.clear();
        for n in 0..win.front.len() {
            let k = win.front[n];
            // domain nodes lie at least one node inside the window: all 4 neighbours exist
            for nb in [k - w, k - 1, k + 1, k + w] {
                let kind = win.nodes[nb].kind;
                if kind == NO_SOIL {
                    continue;
                }
                let (rk, rn) = (win.nodes[k].remainder, win.nodes[nb].remainder);
                if rk > rn {
                    let d = 0.5 * (rk - rn) / 4.0;
                    win.remove(d, k, pass);
                    win.add(d, nb, pass, ground);
                }
                if kind != FREE || (win.undeformed(k) && win.undeformed(nb)) {
                    continue;
                }
                let dy = (win.level(k, ground) + win.nodes[k].remainder)
                    - (win.level(nb, ground) + win.nodes[nb].remainder);
                let d = 0.5 * (dy.abs() - limit) / 4.0;
                if d > 0.0 {
                    let (from, to) = if dy > 0.0 { (k, nb) } else { (nb, k) };
                    win.remove(d, from, pass);
                    win.add(d, to, pass, ground);
                }
            }
        }
        // the next pass: the domain nodes at or next to a node that moved
        win.next.clear();
        for n in 0..win.moved.len() {
            let c = win.moved[n];
            // (a moved node may lie on the window's edge, beyond which nothing is queued)
            for m in [c, c.wrapping_sub(w), c.wrapping_sub(1), c + 1, c + w] {
                if let Some(node) = win.nodes.get_mut(m)
                    && node.in_domain
                    && node.queued != pass
                {
                    node.queued = pass;
                    win.next.push(m);
                }
            }
        }
        std::mem::swap(&mut win.front, &mut win.next);
        if win.front.is_empty() {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use verti_world::SoilParams;

    /// Flat snow, its node grid and fresh soil.
    fn flat_snow() -> (Terrain, SoilLayout, SoilState) {
        let world = Arc::new(crate::testing::soil_world(1.0, SoilParams::SOFT, 0.0));
        let terrain = Terrain::new(&world, 2.0).unwrap();
        let layout = terrain.soil.unwrap();
        (terrain, layout, SoilState::new(Some(&layout)))
    }

    fn pressed(i: i64, j: i64, flow: f64) -> PatchNode {
        PatchNode {
            i,
            j,
            sigma: 1e4,
            flow,
            hit: -0.1,
        }
    }

    /// Runs one step's bulldozing on flat snow from `state`; (heap, remainder) of node (i, j)
    /// afterwards.
    fn run(
        (terrain, layout, mut state): (Terrain, SoilLayout, SoilState),
        nodes: &[PatchNode],
    ) -> impl Fn(i64, i64) -> (f64, f64) + use<> {
        bulldoze(
            &terrain,
            &layout,
            &mut state,
            nodes,
            0..nodes.len(),
            [0..0, 0..0],
        );
        move |i, j| {
            let node = state.node(layout.locate(i, j).unwrap());
            (node.heap, node.remainder)
        }
    }

    /// One pressed node displacing 4 cm: its four neighbours, the rim, take 1 cm each (SCM's
    /// flow factor 1 shares the displaced volume equally), and 1-cm steps are far below the
    /// 55° at which soil slides, so nothing else moves.
    #[test]
    fn the_displaced_volume_is_shared_by_the_rim() {
        let at = run(flat_snow(), &[pressed(0, 0, 0.04)]);
        for (i, j) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            let (heap, rem) = at(i, j);
            assert!(
                (heap - 0.01).abs() < 1e-7 && rem == 0.0,
                "({i},{j}): {heap} {rem}"
            );
        }
        for (i, j) in [(0, 0), (1, 1), (2, 0), (-2, 0), (0, 3)] {
            assert_eq!(at(i, j), (0.0, 0.0), "({i},{j})");
        }
    }

    /// A rim node with the wheel 4 mm above it rises 4 mm at most: the rest of its share waits
    /// as remainder and flows on to neighbours with less (SCM's clamp), so no soil ever stands
    /// inside the wheel, and no volume is made.
    #[test]
    fn heaped_soil_never_rises_through_the_wheel() {
        let mut nodes = vec![pressed(0, 0, 0.04)];
        nodes.push(PatchNode {
            i: 1,
            j: 0,
            sigma: 0.0,
            flow: 0.0,
            hit: 0.004,
        });
        let at = run(flat_snow(), &nodes);
        let (heap, _) = at(1, 0);
        assert!(heap <= 0.004 + 1e-7, "{heap}");
        let total: f64 = (-5..=5)
            .flat_map(|i| (-5..=5).map(move |j| (i, j)))
            .map(|(i, j)| {
                let (h, r) = at(i, j);
                h + r
            })
            .sum();
        // SCM's removal takes a node's level with its remainder: the quirk loses soil, never
        // makes it
        assert!(total <= 0.04 + 1e-6 && total > 0.03, "{total}");
        // the share that did not fit went to the other neighbours of (1, 0)
        assert!(at(2, 0).0 > 0.0 && at(1, 1).0 > 0.0);
    }

    /// A 0.5-m spike of heaped soil next to the patch is a step far steeper than 55°: the
    /// erosion slides it onto its free neighbours, conserving volume (no remainder is
    /// involved), and the step shrinks.
    #[test]
    fn steps_steeper_than_the_erosion_angle_slide() {
        let (terrain, layout, mut state) = flat_snow();
        state.set_heap(layout.locate(0, 2).unwrap(), 0.5, 0.0);
        let at = run((terrain, layout, state), &[pressed(0, 0, 0.0)]);
        let (spike, _) = at(0, 2);
        assert!(spike < 0.5 && spike > 0.143, "{spike}");
        let total: f64 = (-6..=6)
            .flat_map(|i| (-6..=6).map(move |j| (i, j)))
            .map(|(i, j)| at(i, j).0)
            .sum();
        assert!((total - 0.5).abs() < 1e-6, "{total}");
        for (i, j) in [(1, 2), (-1, 2), (0, 3)] {
            assert!(at(i, j).0 > 0.0, "({i},{j}) got nothing");
        }
    }
}
