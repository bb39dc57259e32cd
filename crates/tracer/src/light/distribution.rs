//! A discrete distribution sampled by inverting its CDF, with the remainder of the uniform
//! number handed back rescaled so the caller can reuse it (pbrt-v4 `SampleDiscrete`): a light
//! chosen with u.x still gets a stratified u.x for its own position.

/// Discrete probabilities proportional to non-negative weights.
#[derive(Clone, Debug, Default)]
pub struct Distribution {
    /// cdf[i] = Σ_{j<i} p_j; cdf.len() = n + 1, cdf[n] = 1.
    cdf: Vec<f32>,
    pmf: Vec<f32>,
}

impl Distribution {
    /// The distribution of `weights` (finite, ≥ 0); `None` if they sum to zero.
    pub fn new(weights: &[f64]) -> Option<Self> {
        let total: f64 = weights.iter().sum();
        if !(total > 0.0) || !total.is_finite() {
            return None;
        }
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0);
        for w in weights {
            acc += w;
            cdf.push((acc / total) as f32);
        }
        *cdf.last_mut().expect("non-empty") = 1.0;
        let pmf = weights.iter().map(|w| (w / total) as f32).collect();
        Some(Self { cdf, pmf })
    }

    /// Number of outcomes.
    pub fn len(&self) -> usize {
        self.pmf.len()
    }

    /// True when there are no outcomes.
    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }

    /// Probability of outcome `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }

    /// Picks an outcome with `u` ∈ [0, 1): (index, its probability, u rescaled to [0, 1)).
    #[inline]
    pub fn sample(&self, u: f32) -> (usize, f32, f32) {
        // Largest i with cdf[i] ≤ u, skipping zero-probability outcomes.
        let n = self.pmf.len();
        let i = (self.cdf.partition_point(|&c| c <= u)).clamp(1, n) - 1;
        let p = self.pmf[i];
        let rest = if p > 0.0 { ((u - self.cdf[i]) / p).clamp(0.0, 1.0 - f32::EPSILON / 2.0) } else { 0.0 };
        (i, p, rest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_in_proportion_and_reuses_u() {
        let d = Distribution::new(&[1.0, 0.0, 3.0]).unwrap();
        let mut counts = [0u32; 3];
        for k in 0..4000 {
            let (i, p, rest) = d.sample(k as f32 / 4000.0);
            counts[i] += 1;
            assert_eq!(p, d.pmf(i));
            assert!((0.0..1.0).contains(&rest));
        }
        assert_eq!(counts, [1000, 0, 3000]);
        assert!(Distribution::new(&[0.0, 0.0]).is_none());
        assert!(Distribution::new(&[]).is_none());
    }
}
