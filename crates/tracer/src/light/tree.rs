//! A light BVH (docs/design/tracer.md §3.3; Conty & Kulla 2018; pbrt-v4 `BVHLightSampler`): a binary
//! tree over the scene's finite lights, one light per leaf, each node holding the
//! [`LightBounds`] of its subtree. A light is chosen for a receiver by walking down from the
//! root, taking each child with probability ∝ its importance there and rescaling the one
//! random number as it goes, so that what is left of it still places the point on the light.
//! The probability of a given light is the product along its path, found again by its bit
//! trail (for MIS when a BSDF ray reaches an emitter). As in pbrt-v4, a walk may end without a
//! light where a node's bounds admit the receiver but neither child's do: no light below can
//! light it then, so that costs a sample, never bias. Built once, serially: the same scene
//! gives the same tree.

use super::bounds::LightBounds;
use glam::{DVec3, Vec3};

/// One node: a leaf (one light) or an inner node whose first child is the next node.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: LightBounds,
    /// A leaf's light, or an inner node's second child.
    index: u32,
    leaf: bool,
}

/// A binary tree of light bounds for choosing a light by its importance to a receiver.
#[derive(Clone, Debug)]
pub struct LightTree {
    /// Depth-first order: the root first, every inner node followed by its first child.
    nodes: Vec<Node>,
    /// Per light: its path from the root, bit k set where depth k takes the second child.
    trails: Vec<u64>,
}

/// Buckets per axis for the split search (pbrt-v4's 12).
const BUCKETS: usize = 12;

/// The largest f32 below 1: a rescaled number stays in [0, 1).
pub(super) const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

impl LightTree {
    /// The tree over `lights` (light i is `lights[i]`); `None` when there are none.
    pub fn build(lights: &[LightBounds]) -> Option<Self> {
        if lights.is_empty() {
            return None;
        }
        let n = lights.len();
        let mut tree = Self { nodes: Vec::with_capacity(2 * n - 1), trails: vec![0; n] };
        let mut order: Vec<u32> = (0..n as u32).collect();
        // Bit trails hold 64 turns: below this depth every split halves its lights, so even the
        // most lopsided cost-driven splits above it cannot run out of bits.
        let free_depth = 64 - n.next_power_of_two().trailing_zeros();
        tree.build_node(lights, &mut order, 0, 0, free_depth);
        Some(tree)
    }

    /// Appends the subtree over `order` at `depth` (reached by `trail`); returns its bounds.
    fn build_node(
        &mut self,
        lights: &[LightBounds],
        order: &mut [u32],
        depth: u32,
        trail: u64,
        free_depth: u32,
    ) -> LightBounds {
        if let [light] = *order {
            self.nodes.push(Node { bounds: lights[light as usize], index: light, leaf: true });
            self.trails[light as usize] = trail;
            return lights[light as usize];
        }
        let mid = (depth < free_depth).then(|| split(lights, order)).flatten().unwrap_or_else(|| {
            split_in_half(lights, order);
            order.len() / 2
        });
        let at = self.nodes.len();
        self.nodes.push(Node { bounds: lights[order[0] as usize], index: 0, leaf: false });
        let (first, second) = order.split_at_mut(mid);
        let b0 = self.build_node(lights, first, depth + 1, trail, free_depth);
        let second_index = self.nodes.len() as u32;
        let b1 = self.build_node(lights, second, depth + 1, trail | (1 << depth), free_depth);
        let bounds = b0.union(&b1);
        self.nodes[at] = Node { bounds, index: second_index, leaf: false };
        bounds
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.trails.len()
    }

    /// True when the tree holds no light (never: `build` returns `None` then).
    pub fn is_empty(&self) -> bool {
        self.trails.is_empty()
    }

    /// Chooses a light for a receiver at `p` whose light arrives in the hemisphere around unit
    /// `n` (from anywhere for `n` zero), with `u` ∈ [0, 1): (light, its probability, `u` rescaled to [0, 1)). `None` when no
    /// light can reach the receiver.
    #[inline(always)]
    pub fn sample(&self, p: Vec3, n: Vec3, mut u: f32) -> Option<(u32, f32, f32)> {
        let mut at = 0;
        let mut pmf = 1.0f32;
        loop {
            let node = &self.nodes[at];
            if node.leaf {
                return Some((node.index, pmf, u));
            }
            let second = node.index as usize;
            let c0 = self.nodes[at + 1].bounds.importance(p, n);
            let c1 = self.nodes[second].bounds.importance(p, n);
            let sum = c0 + c1;
            if !(sum > 0.0) {
                return None;
            }
            let p0 = c0 / sum;
            if u < p0 {
                pmf *= p0;
                u = (u / p0).min(ONE_MINUS_EPSILON);
                at += 1;
            } else {
                pmf *= c1 / sum;
                u = ((u - p0) / (1.0 - p0)).min(ONE_MINUS_EPSILON);
                at = second;
            }
        }
    }

    /// The probability that [`LightTree::sample`] chooses `light` for the receiver (`p`, `n`):
    /// the same products along the light's path, bit for bit.
    #[inline]
    pub fn pmf(&self, p: Vec3, n: Vec3, light: u32) -> f32 {
        let mut trail = self.trails[light as usize];
        let mut at = 0;
        let mut pmf = 1.0f32;
        loop {
            let node = &self.nodes[at];
            if node.leaf {
                return pmf;
            }
            let second = node.index as usize;
            let c0 = self.nodes[at + 1].bounds.importance(p, n);
            let c1 = self.nodes[second].bounds.importance(p, n);
            let sum = c0 + c1;
            if !(sum > 0.0) {
                return 0.0;
            }
            if trail & 1 == 0 {
                pmf *= c0 / sum;
                at += 1;
            } else {
                pmf *= c1 / sum;
                at = second;
            }
            trail >>= 1;
        }
    }
}

/// The split of `order` with the least surface-area–orientation cost (Conty & Kulla 2018
/// eq. 2; pbrt-v4 `EvaluateCost`): over 12 buckets of box centres per axis, the cost of a side
/// is its intensity × orientation measure × box area, times the node's largest extent over its
/// extent along the axis (long nodes prefer to be cut across). Partitions `order` (keeping each
/// side's order) and returns the size of the first side; `None` when the centres coincide.
fn split(lights: &[LightBounds], order: &mut [u32]) -> Option<usize> {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let (mut c_lo, mut c_hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for &i in order.iter() {
        let b = &lights[i as usize];
        (lo, hi) = (lo.min(b.lo), hi.max(b.hi));
        (c_lo, c_hi) = (c_lo.min(b.centre()), c_hi.max(b.centre()));
    }
    let extent = (hi - lo).as_dvec3();
    // Points and flat clusters have no area; a floor on each side keeps their costs apart.
    let min_side = 1e-3 * extent.max_element();
    let bucket = |b: &LightBounds, dim: usize| {
        let t = (b.centre()[dim] - c_lo[dim]) / (c_hi[dim] - c_lo[dim]);
        ((t * BUCKETS as f32) as usize).min(BUCKETS - 1)
    };
    let mut best: Option<(f64, usize, usize)> = None;
    for dim in 0..3 {
        if !(c_hi[dim] > c_lo[dim]) {
            continue;
        }
        let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        for &i in order.iter() {
            let b = &lights[i as usize];
            let slot = &mut buckets[bucket(b, dim)];
            *slot = Some(slot.map_or(*b, |s| s.union(b)));
        }
        let cost = |b: &LightBounds| {
            let d = (b.hi - b.lo).as_dvec3().max(DVec3::splat(min_side));
            let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
            b.intensity as f64 * b.orientation_measure() * area * extent.max_element() / extent[dim]
        };
        // Costs of everything below each cut, then above it.
        let mut below = [f64::INFINITY; BUCKETS];
        let mut acc: Option<LightBounds> = None;
        for (k, b) in buckets.iter().enumerate().take(BUCKETS - 1) {
            acc = union_opt(acc, *b);
            below[k] = acc.as_ref().map_or(f64::INFINITY, cost);
        }
        let mut acc: Option<LightBounds> = None;
        for k in (0..BUCKETS - 1).rev() {
            acc = union_opt(acc, buckets[k + 1]);
            let c = below[k] + acc.as_ref().map_or(f64::INFINITY, cost);
            if c.is_finite() && best.is_none_or(|(b, _, _)| c < b) {
                best = Some((c, dim, k));
            }
        }
    }
    let (_, dim, cut) = best?;
    let (first, second): (Vec<u32>, Vec<u32>) =
        order.iter().partition(|&&i| bucket(&lights[i as usize], dim) <= cut);
    let mid = first.len();
    order[..mid].copy_from_slice(&first);
    order[mid..].copy_from_slice(&second);
    Some(mid)
}

/// Orders `order` along the axis where the box centres spread most (ties by light index), so
/// that its halves are split in the middle.
fn split_in_half(lights: &[LightBounds], order: &mut [u32]) {
    let (mut c_lo, mut c_hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for &i in order.iter() {
        let c = lights[i as usize].centre();
        (c_lo, c_hi) = (c_lo.min(c), c_hi.max(c));
    }
    let dim = (c_hi - c_lo).max_position();
    order.sort_by(|&a, &b| {
        let (ca, cb) = (lights[a as usize].centre()[dim], lights[b as usize].centre()[dim]);
        ca.total_cmp(&cb).then(a.cmp(&b))
    });
}

fn union_opt(a: Option<LightBounds>, b: Option<LightBounds>) -> Option<LightBounds> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.union(&b)),
        (a, b) => a.or(b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{EmissiveTriangle, PointLight, SpotLight};
    use crate::scene::SpotFalloff;
    use crate::test_support::Rng;

    /// A light of the test scenes, and whether it can light a receiver.
    enum TestLight {
        Triangle(EmissiveTriangle),
        Point(PointLight),
        Spot(SpotLight),
    }

    impl TestLight {
        fn bounds(&self) -> LightBounds {
            match self {
                Self::Triangle(t) => t.bounds(),
                Self::Point(p) => p.bounds(),
                Self::Spot(s) => s.bounds(),
            }
        }

        /// True when some point of the light sends light to `p` arriving clearly inside the
        /// hemisphere around `n` (cosines above 1e-3 on both ends).
        fn can_light(&self, p: Vec3, n: Vec3) -> bool {
            const MARGIN: f32 = 1e-3;
            let receives = |x: Vec3| n.dot((x - p).normalize()) > MARGIN;
            match self {
                Self::Triangle(t) => (0..=16).any(|i| {
                    (0..=16 - i).any(|j| {
                        let (b1, b2) = (i as f32 / 16.0, j as f32 / 16.0);
                        let x = t.p[0] * (1.0 - b1 - b2) + t.p[1] * b1 + t.p[2] * b2;
                        let cos = t.n.dot((p - x).normalize());
                        receives(x) && (cos > MARGIN || (t.two_sided && cos < -MARGIN))
                    })
                }),
                Self::Point(l) => receives(l.position),
                Self::Spot(s) => receives(s.position) && s.falloff((p - s.position).normalize()) > 0.0,
            }
        }
    }

    /// Triangles of random sizes and orientations (every fifth two-sided), point lights and
    /// spot lights of both falloffs, in a box of side 10.
    fn scene(rng: &mut Rng) -> Vec<TestLight> {
        let mut lights = Vec::new();
        for k in 0..60 {
            let c = rng.in_cube(1.0) * 5.0;
            let size = 0.05 + rng.unit();
            let p = [c + rng.in_cube(1.0) * size, c + rng.in_cube(1.0) * size, c + rng.in_cube(1.0) * size];
            let radiance = Vec3::new(rng.unit(), rng.unit(), rng.unit()) * 10.0;
            if let Some(t) = EmissiveTriangle::new(k, p, radiance, k % 5 == 0) {
                lights.push(TestLight::Triangle(t));
            }
        }
        for k in 0..6 {
            let position = rng.in_cube(1.0) * 5.0;
            let intensity = Vec3::splat(1.0 + 20.0 * rng.unit());
            if k % 2 == 0 {
                lights.push(TestLight::Point(PointLight { position, intensity }));
            } else {
                let outer = 0.2 + 1.2 * rng.unit();
                let inner = outer * rng.unit();
                let falloff = if k % 3 == 0 { SpotFalloff::Gltf } else { SpotFalloff::Blender };
                let dir = rng.direction();
                lights.push(TestLight::Spot(SpotLight::new(position, dir, intensity, inner, outer, falloff)));
            }
        }
        lights
    }

    /// A random scene and its tree.
    fn scene_and_tree(rng: &mut Rng) -> (Vec<TestLight>, LightTree) {
        let lights = scene(rng);
        let bounds: Vec<LightBounds> = lights.iter().map(TestLight::bounds).collect();
        let tree = LightTree::build(&bounds).expect("lights");
        (lights, tree)
    }

    /// For random receivers (p, n): each light is sampled as often as its probability says, and
    /// the walk ends without a light (an inner node's bounds admit the receiver, its children's
    /// do not) as often as the probabilities fall short of 1 (200,000 samples, within 5
    /// standard deviations plus one count); `sample` reports exactly the probability `pmf`
    /// computes; a light that can light the receiver never has probability 0. (The share lost
    /// to such ends is printed.)
    #[test]
    fn sampling_matches_brute_force_and_is_conservative() {
        let mut rng = Rng::new(11);
        let (lights, tree) = scene_and_tree(&mut rng);
        assert_eq!(tree.len(), lights.len());
        const N: usize = 200_000;
        let (mut reachable, mut lit, mut lost) = (0, 0, 0.0);
        let within = |count: usize, p: f64| {
            let mean = N as f64 * p;
            (count as f64 - mean).abs() <= 5.0 * (mean * (1.0 - p)).max(0.0).sqrt() + 1.0
        };
        for receiver in 0..40 {
            let p = rng.in_cube(1.0) * 6.0;
            let n = rng.direction();
            let pmfs: Vec<f32> = (0..lights.len() as u32).map(|i| tree.pmf(p, n, i)).collect();
            let total: f64 = pmfs.iter().map(|&x| x as f64).sum();
            for (i, light) in lights.iter().enumerate() {
                if light.can_light(p, n) {
                    reachable += 1;
                    assert!(pmfs[i] > 0.0, "receiver {receiver}: light {i} can light it but has pmf 0");
                }
            }
            assert!(total <= 1.0 + 1e-5, "receiver {receiver}: pmfs sum to {total}");
            if total > 0.0 {
                lit += 1;
                lost += 1.0 - total.min(1.0);
            }
            let mut counts = vec![0usize; lights.len()];
            let mut none = 0;
            for _ in 0..N {
                let Some((i, pmf, rest)) = tree.sample(p, n, rng.unit()) else {
                    none += 1;
                    continue;
                };
                assert_eq!(pmf.to_bits(), pmfs[i as usize].to_bits(), "sample and pmf disagree");
                assert!((0.0..1.0).contains(&rest));
                counts[i as usize] += 1;
            }
            for (i, (&count, &pmf)) in counts.iter().zip(&pmfs).enumerate() {
                assert!(
                    within(count, pmf as f64),
                    "receiver {receiver}, light {i}: {count} samples, expected {:.1}",
                    N as f64 * pmf as f64
                );
            }
            let p_none = (1.0 - total).max(0.0);
            assert!(
                within(none, p_none),
                "receiver {receiver}: {none} ends without a light, expected {p_none}"
            );
        }
        assert!(reachable > 400, "the test scene lights too few receivers ({reachable})");
        assert!(lit > 20, "too few receivers any light reaches ({lit})");
        println!("walks ending without a light where some light reaches: {:.3}", lost / lit as f64);
    }

    /// The rescaled number keeps its stratification: evenly spaced numbers give each light a
    /// run of samples whose rescaled numbers spread evenly over [0, 1).
    #[test]
    fn rescaled_number_stays_uniform() {
        let (lights, tree) = scene_and_tree(&mut Rng::new(3));
        let (p, n) = (Vec3::new(0.5, -0.3, 0.2), Vec3::Y);
        const N: usize = 1 << 18;
        let mut per_light: Vec<Vec<f32>> = vec![Vec::new(); lights.len()];
        for k in 0..N {
            if let Some((i, _, rest)) = tree.sample(p, n, (k as f32 + 0.5) / N as f32) {
                per_light[i as usize].push(rest);
            }
        }
        assert!(per_light.iter().map(Vec::len).sum::<usize>() > N / 2);
        for rests in per_light.iter().filter(|r| r.len() >= 1000) {
            let mean = rests.iter().map(|&r| r as f64).sum::<f64>() / rests.len() as f64;
            let below_quarter = rests.iter().filter(|&&r| r < 0.25).count() as f64 / rests.len() as f64;
            assert!(
                (mean - 0.5).abs() < 0.01 && (below_quarter - 0.25).abs() < 0.01,
                "{mean} {below_quarter}"
            );
        }
    }

    /// One light is a leaf at the root: chosen with probability 1, the number untouched.
    #[test]
    fn one_light_needs_no_walk() {
        let t = EmissiveTriangle::new(0, [Vec3::ZERO, Vec3::X, Vec3::Y], Vec3::ONE, false).unwrap();
        let tree = LightTree::build(&[t.bounds()]).unwrap();
        assert_eq!(tree.sample(Vec3::Z, -Vec3::Z, 0.375), Some((0, 1.0, 0.375)));
        assert_eq!(tree.pmf(Vec3::Z, -Vec3::Z, 0), 1.0);
        assert!(LightTree::build(&[]).is_none());
    }
}
