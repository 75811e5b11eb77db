//! Test helpers shared by the unit tests of every crate and by the integration tests
//! (`tests/support` re-exports them), so each rule is written once: the reference data under
//! `../shared` ([`data`]), Pearson's χ² goodness-of-fit test for sampling code ([`chi2`]) and
//! picture comparisons that keep their evidence ([`pictures`], feature `pictures`).

pub mod chi2;
pub mod data;
#[cfg(feature = "pictures")]
pub mod pictures;
