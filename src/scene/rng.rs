//! The random numbers of a variant: a counter-based generator keyed by `(seed, index,
//! stream)`, so variant `i` draws the same numbers whatever thread, shard or order makes it.
//!
//! Written here (SplitMix64 to key, xoshiro256** to draw) rather than taken from a crate so
//! that the numbers, and so the bytes of every variant, can never change with a dependency
//! update. Each use of randomness in a variant (placement, each randomizer) has its own
//! stream, so adding a randomizer does not move the objects of existing variants.

/// SplitMix64's finalizer: a bijective mix of 64 bits.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A generator for one stream of one variant.
#[derive(Clone, Debug)]
pub(crate) struct Rng {
    s: [u64; 4],
}

impl Rng {
    /// The generator of stream `stream` of variant `index` of a scene seeded `seed`.
    pub(crate) fn new(seed: u64, index: u64, stream: u64) -> Rng {
        // Key the state from all three numbers through chained mixes (distinct inputs give
        // unrelated states), then expand it with SplitMix64 as xoshiro's authors advise.
        let mut x = mix(mix(mix(seed ^ 0x6a09_e667_f3bc_c909) ^ index) ^ stream);
        let mut s = [0u64; 4];
        for word in &mut s {
            x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
            *word = mix(x);
        }
        Rng { s }
    }

    /// The next 64 random bits (xoshiro256**).
    pub(crate) fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// Uniform in `[0, 1)`, with 53 random bits.
    pub(crate) fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[low, high]` (`low` when they are equal).
    pub(crate) fn uniform(&mut self, low: f64, high: f64) -> f64 {
        low + (high - low) * self.unit()
    }

    /// Uniform integer in `[low, high]`, without modulo bias (Lemire's method).
    pub(crate) fn int_in(&mut self, low: u64, high: u64) -> u64 {
        let span = high - low;
        if span == u64::MAX {
            return self.next_u64();
        }
        let n = span + 1;
        loop {
            let m = u128::from(self.next_u64()) * u128::from(n);
            let lo = m as u64;
            if lo >= n || lo >= n.wrapping_neg() % n {
                return low + (m >> 64) as u64;
            }
        }
    }

    /// Standard normal (Box-Muller; the second value is dropped so that every draw uses a
    /// fixed count of numbers).
    pub(crate) fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.unit(); // (0, 1]: ln never sees 0
        let u2 = self.unit();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    /// An index drawn with probability proportional to `weights` (all finite, >= 0, and
    /// not all zero: checked when the scene is loaded).
    pub(crate) fn weighted(&mut self, weights: &[f64]) -> usize {
        let total: f64 = weights.iter().sum();
        let mut x = self.unit() * total;
        for (i, &w) in weights.iter().enumerate() {
            if x < w {
                return i;
            }
            x -= w;
        }
        // Rounding can leave x just above the last weight: the last positive one.
        weights.iter().rposition(|&w| w > 0.0).unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_key_same_numbers_other_key_other_numbers() {
        let draw = |seed, index, stream| {
            let mut r = Rng::new(seed, index, stream);
            (0..4).map(|_| r.next_u64()).collect::<Vec<_>>()
        };
        assert_eq!(draw(1, 2, 3), draw(1, 2, 3));
        assert_ne!(draw(1, 2, 3), draw(1, 3, 2));
        assert_ne!(draw(1, 2, 3), draw(2, 2, 3));
        assert_ne!(draw(0, 0, 0), draw(0, 0, 1));
    }

    #[test]
    fn pinned_values() {
        // These numbers are part of the output format: every variant's bytes depend on them.
        // A change here changes every variant of every scene file users have.
        let mut r = Rng::new(7, 42, 0);
        let first = r.next_u64();
        let mut again = Rng::new(7, 42, 0);
        assert_eq!(first, again.next_u64());
        assert_eq!(format!("{first:016x}"), PINNED);
    }
    const PINNED: &str = "ce2f2cb797b0cb85";

    #[test]
    fn xoshiro_matches_its_reference() {
        // The reference implementation (xoshiro256starstar.c) seeded {1, 2, 3, 4} gives
        // 11520, then 0, then 1509978240 as its first outputs.
        let mut r = Rng { s: [1, 2, 3, 4] };
        assert_eq!(
            [r.next_u64(), r.next_u64(), r.next_u64()],
            [11520, 0, 1509978240]
        );
    }

    #[test]
    fn distributions_stay_in_range_and_are_spread() {
        let mut r = Rng::new(1, 1, 1);
        let mut counts = [0usize; 4];
        for _ in 0..40_000 {
            let u = r.uniform(-2.0, 3.0);
            assert!((-2.0..=3.0).contains(&u));
            let k = r.int_in(3, 6);
            assert!((3..=6).contains(&k));
            counts[(k - 3) as usize] += 1;
        }
        // Each of four outcomes near 10,000: a biased draw would miss by far more than 5 sigma.
        for c in counts {
            assert!((9_500..=10_500).contains(&c), "{counts:?}");
        }
        let w = [0.0, 3.0, 1.0];
        let mut hits = [0usize; 3];
        for _ in 0..40_000 {
            hits[r.weighted(&w)] += 1;
        }
        assert_eq!(hits[0], 0);
        assert!((29_400..=30_600).contains(&hits[1]), "{hits:?}");
        let n: Vec<f64> = (0..40_000).map(|_| r.normal()).collect();
        let mean = n.iter().sum::<f64>() / n.len() as f64;
        let var = n.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n.len() as f64;
        assert!(
            mean.abs() < 0.025 && (var - 1.0).abs() < 0.03,
            "{mean} {var}"
        );
    }
}
