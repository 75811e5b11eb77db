//! Pearson's χ² goodness-of-fit test, as Mitsuba tests its sampling code: samples are counted in
//! cells, each cell's expected count is the target density integrated over it times the sample
//! count, and the test fails when the p-value of the χ² statistic falls below a significance
//! level corrected for the number of tests run (Šidák: α' = 1 − (1 − α)^(1/tests)). Cells are
//! taken in order of increasing expectation and those expecting fewer than 5 samples are pooled
//! (until the pool expects 5), so the χ² approximation of the statistic holds.

use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The smallest expected count a cell may have before it is pooled.
pub const MIN_EXPECTED: f64 = 5.0;

/// The significance level of one of `tests` independent tests that together keep `alpha`.
pub fn sidak(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests.max(1) as f64)
}

/// The outcome of one test.
#[derive(Clone, Debug)]
pub struct Chi2 {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// Cells merged into the low-expectation pool.
    pub pooled: usize,
}

impl std::fmt::Display for Chi2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "χ² {:.1} on {} degrees of freedom, p = {:.3e} ({} cells pooled)",
            self.statistic, self.dof, self.p_value, self.pooled
        )
    }
}

/// The χ² statistic and its p-value of `observed` counts against `expected` ones (same order,
/// same total up to the caller's integration error). An error when a cell that expects nothing
/// holds samples, or when fewer than two cells remain.
pub fn chi2(observed: &[f64], expected: &[f64]) -> Result<Chi2, String> {
    assert_eq!(observed.len(), expected.len(), "one expectation per cell");
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut statistic, mut cells) = (0.0, 0usize);
    let (mut pool_observed, mut pool_expected, mut pooled) = (0.0, 0.0, 0usize);
    for i in order {
        let (o, e) = (observed[i], expected[i]);
        if !(e.is_finite() && e >= 0.0) {
            return Err(format!("cell {i} expects {e} samples"));
        }
        if e == 0.0 {
            if o > 0.0 {
                return Err(format!("cell {i} expects no sample but holds {o}"));
            }
            continue;
        }
        if e < MIN_EXPECTED || (pooled > 0 && pool_expected < MIN_EXPECTED) {
            pool_observed += o;
            pool_expected += e;
            pooled += 1;
        } else {
            statistic += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pooled > 0 {
        statistic += (pool_observed - pool_expected).powi(2) / pool_expected;
        cells += 1;
    }
    if cells < 2 {
        return Err(format!("{cells} cell(s) after pooling: nothing to test"));
    }
    let dof = cells - 1;
    let p_value = ChiSquared::new(dof as f64)
        .map_err(|e| e.to_string())?
        .sf(statistic);
    Ok(Chi2 {
        statistic,
        dof,
        p_value,
        pooled,
    })
}

/// [`chi2`] held to `significance`: Ok with the outcome when the counts are consistent with the
/// expectation, Err with the outcome when not.
pub fn chi2_test(observed: &[f64], expected: &[f64], significance: f64) -> Result<Chi2, String> {
    let outcome = chi2(observed, expected)?;
    if outcome.p_value.is_finite() && outcome.p_value >= significance {
        Ok(outcome)
    } else {
        Err(format!("{outcome} < significance {significance:.1e}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64 uniforms: seeded, no dependency.
    fn uniforms(seed: u64) -> impl Iterator<Item = f64> {
        let mut s = seed;
        std::iter::from_fn(move || {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            Some(((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64)
        })
    }

    /// Samples of the density 2x on [0, 1) (x = √u) in 20 cells, against that density and
    /// against a slightly wrong one (the mode of failure the test exists for).
    #[test]
    fn accepts_the_right_density_and_rejects_a_perturbed_one() {
        let (n, cells) = (100_000, 20);
        let mut observed = vec![0.0; cells];
        for u in uniforms(7).take(n) {
            observed[((u.sqrt() * cells as f64) as usize).min(cells - 1)] += 1.0;
        }
        let expected = |k: f64| -> Vec<f64> {
            // ∫ of (1 − k)·2x + k·3x² over each cell
            (0..cells)
                .map(|i| {
                    let (a, b) = (i as f64 / cells as f64, (i + 1) as f64 / cells as f64);
                    n as f64 * ((1.0 - k) * (b * b - a * a) + k * (b.powi(3) - a.powi(3)))
                })
                .collect()
        };
        let level = sidak(0.01, 2);
        let right = chi2_test(&observed, &expected(0.0), level).unwrap();
        assert_eq!(right.dof, cells - 1);
        let wrong = chi2_test(&observed, &expected(0.05), level);
        assert!(wrong.is_err(), "a 5 % admixture of 3x² passed: {wrong:?}");
    }

    #[test]
    fn low_expectations_are_pooled_and_impossible_samples_fail() {
        // The cells expecting 3 and 4 samples are pooled into one expecting 7.
        let outcome = chi2(&[10.0, 20.0, 3.0, 4.0], &[10.0, 20.0, 3.0, 4.0]).unwrap();
        assert_eq!((outcome.pooled, outcome.dof), (2, 2));
        assert!(outcome.statistic.abs() < 1e-12 && outcome.p_value > 0.99);
        assert!(chi2(&[10.0, 1.0], &[11.0, 0.0]).is_err());
        assert!(chi2(&[10.0], &[10.0]).is_err());
        assert!((sidak(0.01, 1) - 0.01).abs() < 1e-15);
        assert!(sidak(0.01, 10) < 0.01 / 9.9 && sidak(0.01, 10) > 0.01 / 10.0);
    }
}
