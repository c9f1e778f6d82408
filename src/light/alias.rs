//! Walker's alias method (Vose's construction): one of n items in proportion to its weight,
//! in constant time per draw.

/// The largest `f32` below 1.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

/// A table that picks item i with probability `weights[i] / Σ weights`.
#[derive(Clone, Debug, PartialEq)]
pub struct AliasTable {
    /// Per column: the probability of keeping the column's own item (else its alias).
    keep: Vec<f32>,
    /// Per column: the item taken when the column's own is not kept.
    alias: Vec<u32>,
    /// Each item's probability, for [`AliasTable::pmf`].
    pmf: Vec<f32>,
}

impl AliasTable {
    /// A table for `weights` (powers, say). `None` when there is nothing to pick: no weights,
    /// a negative or non-finite one, or all zero. Items of weight zero are never picked.
    pub fn new(weights: &[f32]) -> Option<AliasTable> {
        if weights.is_empty() || weights.len() > u32::MAX as usize {
            return None;
        }
        if weights.iter().any(|w| !w.is_finite() || *w < 0.0) {
            return None;
        }
        let total: f64 = weights.iter().map(|&w| f64::from(w)).sum();
        if total <= 0.0 || !total.is_finite() {
            return None;
        }
        let n = weights.len();
        let pmf: Vec<f64> = weights.iter().map(|&w| f64::from(w) / total).collect();
        // Columns of height 1: each item's probability times n, the short ones topped up
        // from the tall ones (f64, so the round-off left at the end is far below f32's).
        let mut scaled: Vec<f64> = pmf.iter().map(|p| p * n as f64).collect();
        let mut keep = vec![1.0f32; n];
        let mut alias: Vec<u32> = (0..n as u32).collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) =
            (0..n).partition(|&i| scaled[i] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            keep[s] = scaled[s] as f32;
            alias[s] = l as u32;
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What is left has height 1 up to round-off: kept whole.
        Some(AliasTable {
            keep,
            alias,
            pmf: pmf.iter().map(|&p| p as f32).collect(),
        })
    }

    /// The number of items.
    pub fn len(&self) -> usize {
        self.pmf.len()
    }

    /// Whether the table has no items (never: [`AliasTable::new`] refuses that).
    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }

    /// Item i's probability.
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }

    /// An item from one uniform number `u` in `[0, 1)`, and its probability: `u·n` picks a
    /// column, its fraction decides between the column's item and its alias.
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let (i, p, _) = self.sample_remapped(u);
        (i, p)
    }

    /// [`AliasTable::sample`], and `u` made uniform again for another use: where in its part
    /// of the column `u` fell, rescaled to `[0, 1)` (uniform given the item, as each column's
    /// part is; pbrt-v4's alias table does the same). So one number picks the item and
    /// places a point on it.
    pub fn sample_remapped(&self, u: f32) -> (usize, f32, f32) {
        let n = self.len();
        let x = u.clamp(0.0, 1.0) * n as f32;
        let column = (x as usize).min(n - 1);
        let up = (x - column as f32).min(1.0);
        let keep = self.keep[column];
        let (i, rest) = if up < keep {
            (column, up / keep)
        } else {
            (self.alias[column] as usize, (up - keep) / (1.0 - keep))
        };
        (i, self.pmf[i], rest.min(ONE_BELOW))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn items_are_picked_in_proportion_to_their_weights() {
        let weights = [14.0, 2.0, 0.0, 2.0, 0.5, 30.0, 1.0];
        let t = AliasTable::new(&weights).unwrap();
        let total: f32 = weights.iter().sum();
        let mut rng = Rng::seeded(3);
        let n = 1_000_000;
        let mut counts = [0u32; 7];
        for _ in 0..n {
            let (i, p) = t.sample(rng.next_f32());
            assert_eq!(p, t.pmf(i));
            counts[i] += 1;
        }
        assert_eq!(counts[2], 0, "an item of weight 0 was picked");
        let mut chi2 = 0.0;
        for (i, &w) in weights.iter().enumerate() {
            assert!((t.pmf(i) - w / total).abs() < 1e-7);
            if w > 0.0 {
                let e = f64::from(w / total) * f64::from(n);
                chi2 += (f64::from(counts[i]) - e).powi(2) / e;
            }
        }
        // 5 degrees of freedom: P(χ² > 20.5) = 0.001.
        assert!(chi2 < 20.5, "χ² = {chi2}, counts {counts:?}");
    }

    #[test]
    fn the_remapped_number_is_uniform_given_the_item() {
        // Per item, the remapped numbers fall evenly into 8 bins (χ² over seeded draws), and
        // the item is the one `sample` picks.
        let weights = [14.0, 2.0, 0.0, 2.0, 0.5, 30.0, 1.0];
        let t = AliasTable::new(&weights).unwrap();
        let mut rng = Rng::seeded(8);
        let mut bins = [[0u32; 8]; 7];
        for _ in 0..400_000 {
            let u = rng.next_f32();
            let (i, p, rest) = t.sample_remapped(u);
            assert_eq!((i, p), t.sample(u));
            assert!((0.0..1.0).contains(&rest), "{rest}");
            bins[i][(rest * 8.0) as usize] += 1;
        }
        for (i, b) in bins.iter().enumerate() {
            let n: u32 = b.iter().sum();
            if weights[i] == 0.0 {
                assert_eq!(n, 0);
                continue;
            }
            let e = f64::from(n) / 8.0;
            let chi2: f64 = b.iter().map(|&c| (f64::from(c) - e).powi(2) / e).sum();
            // 7 degrees of freedom: P(χ² > 24.3) = 0.001.
            assert!(chi2 < 24.3, "item {i}: χ² = {chi2}, {b:?}");
        }
    }

    #[test]
    fn every_column_is_a_whole_unit() {
        // Column masses add back up to each item's probability.
        let mut rng = Rng::seeded(9);
        for n in [1usize, 2, 3, 17, 1000] {
            let weights: Vec<f32> = (0..n).map(|_| rng.next_f32().powi(3) * 100.0).collect();
            let t = AliasTable::new(&weights).unwrap();
            let mut mass = vec![0.0f64; n];
            for c in 0..n {
                mass[c] += f64::from(t.keep[c]) / n as f64;
                mass[t.alias[c] as usize] += (1.0 - f64::from(t.keep[c])) / n as f64;
            }
            for (i, m) in mass.iter().enumerate() {
                assert!((m - f64::from(t.pmf(i))).abs() < 1e-6, "{n}: {i}");
            }
            // The ends of the unit interval stay in range.
            assert!(t.sample(0.0).0 < n && t.sample(0.999_999_94).0 < n && t.sample(1.0).0 < n);
        }
    }

    #[test]
    fn nothing_to_pick_is_refused() {
        assert!(AliasTable::new(&[]).is_none());
        assert!(AliasTable::new(&[0.0, 0.0]).is_none());
        assert!(AliasTable::new(&[1.0, -1.0]).is_none());
        assert!(AliasTable::new(&[1.0, f32::NAN]).is_none());
        assert!(AliasTable::new(&[f32::INFINITY]).is_none());
        assert_eq!(AliasTable::new(&[0.0, 5.0]).unwrap().sample(0.1), (1, 1.0));
    }
}
