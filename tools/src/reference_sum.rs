//! Converged references as a sum of sample batches in one fixed order, so that a reference split
//! across processes merges into the very bytes one process writes.
//!
//! Samples are taken in batches of [`BATCH_SPP`] consecutive sample indices (a sample index draws
//! the same paths wherever it is rendered: `Renderer::render_reference_samples`). Each batch's
//! mean comes from the GPU in f32 and becomes an exact f64 sum (mean × count); the batches are
//! added pairwise in f64 along a fixed binary tree over their indices — a range splits after the
//! largest power of two shorter than it — and the total over the sample count, rounded to f32, is
//! the reference. Floating-point addition is not associative, which is why the order is fixed:
//! an aligned block of a power-of-two number of batches (see [`blocks`]) is a subtree, so a job
//! that sums one block and a merge that adds the blocks' sums along the same tree perform exactly
//! the additions of a single process.

use anyhow::{bail, Context, Result};
use fovea_renderer::frame::CameraPose;
use fovea_renderer::pipeline::Renderer;
use std::io::{BufRead, BufReader, Read, Write};
use std::ops::Range;
use std::path::Path;

/// Samples per batch: the unit of the fixed summation order (and of a sweep's reference jobs).
pub const BATCH_SPP: u32 = 16;

/// Batches of a reference of `spp` samples (the last one may be shorter).
pub fn batch_count(spp: u32) -> u32 {
    spp.div_ceil(BATCH_SPP)
}

/// Sample indices of batch `b` of a reference of `spp` samples.
pub fn batch_samples(spp: u32, b: u32) -> Range<u32> {
    b * BATCH_SPP..((b + 1) * BATCH_SPP).min(spp)
}

/// Where the tree splits `range` (at least two batches): after the largest power of two shorter
/// than it.
fn split(range: &Range<u32>) -> u32 {
    let len = range.end - range.start;
    debug_assert!(len >= 2);
    range.start + (1u32 << (31 - (len - 1).leading_zeros()))
}

/// Aligned blocks of `per_block` batches (a power of two) covering `0..batches`: each is a node of
/// the summation tree, so their sums merge exactly.
pub fn blocks(batches: u32, per_block: u32) -> Vec<Range<u32>> {
    assert!(per_block.is_power_of_two());
    (0..batches.div_ceil(per_block))
        .map(|j| j * per_block..((j + 1) * per_block).min(batches))
        .collect()
}

/// Per-pixel RGBA sums of a range of batches, in f64.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleSum {
    pub width: u32,
    pub height: u32,
    /// The reference's samples per pixel (all batches, not only these).
    pub spp: u32,
    pub batches: Range<u32>,
    pub texels: Texels,
}

impl SampleSum {
    /// The reference: the sum over all samples divided by their count, rounded to f32.
    pub fn mean(&self) -> Result<Vec<[f32; 4]>> {
        if self.batches != (0..batch_count(self.spp)) {
            bail!(
                "a sum of batches {:?} is not the whole reference (batches 0..{})",
                self.batches,
                batch_count(self.spp)
            );
        }
        let n = self.spp as f64;
        Ok(self
            .texels
            .iter()
            .map(|t| t.map(|c| (c / n) as f32))
            .collect())
    }
}

/// Per-pixel RGBA sums in f64.
pub type Texels = Vec<[f64; 4]>;

/// The tree sum over `range`: `leaf` gives a node's sum when it has one (a rendered batch, a
/// stored block); nodes it leaves out are the sums of their two children.
pub fn tree_sum(
    range: Range<u32>,
    leaf: &mut dyn FnMut(&Range<u32>) -> Result<Option<Texels>>,
) -> Result<Texels> {
    if let Some(sum) = leaf(&range)? {
        return Ok(sum);
    }
    if range.end - range.start < 2 {
        bail!("no sum for batches {range:?}");
    }
    let mid = split(&range);
    let mut left = tree_sum(range.start..mid, leaf)?;
    let right = tree_sum(mid..range.end, leaf)?;
    if left.len() != right.len() {
        bail!("the sums of batches {range:?} differ in size");
    }
    for (l, r) in left.iter_mut().zip(&right) {
        for c in 0..4 {
            l[c] += r[c];
        }
    }
    Ok(left)
}

/// Renders batches `batches` of a reference of `spp` samples at `pose` and sums them along the
/// tree. `after_batch` runs after each batch with the samples done so far (progress, and a stop
/// requested by a signal: its error ends the render).
pub fn render_sum(
    renderer: &mut Renderer,
    pose: &CameraPose,
    spp: u32,
    max_depth: u32,
    batches: Range<u32>,
    after_batch: &mut dyn FnMut(u32) -> Result<()>,
) -> Result<SampleSum> {
    if spp == 0 || batches.start >= batches.end || batches.end > batch_count(spp) {
        bail!(
            "batches {batches:?} are not within the {} of a {spp}-sample reference",
            batch_count(spp)
        );
    }
    let mut done = 0;
    let texels = tree_sum(batches.clone(), &mut |range| {
        if range.end - range.start != 1 {
            return Ok(None);
        }
        let samples = batch_samples(spp, range.start);
        let count = samples.len() as f64;
        let mean = renderer.render_reference_samples(pose, samples.clone(), max_depth, |_| {})?;
        done += samples.len() as u32;
        after_batch(done)?;
        // Exact: a 24-bit mantissa times a count below 2^5 fits in f64's 53 bits.
        Ok(Some(
            mean.iter().map(|t| t.map(|c| c as f64 * count)).collect(),
        ))
    })?;
    let size = renderer.space().screen_size();
    Ok(SampleSum {
        width: size.x,
        height: size.y,
        spp,
        batches,
        texels,
    })
}

/// A whole reference of `spp` samples at `pose` (what `fovea reference` and `fovea quality`
/// write): [`render_sum`] over every batch, divided by `spp`.
pub fn render(
    renderer: &mut Renderer,
    pose: &CameraPose,
    spp: u32,
    max_depth: u32,
    after_batch: &mut dyn FnMut(u32) -> Result<()>,
) -> Result<Vec<[f32; 4]>> {
    render_sum(
        renderer,
        pose,
        spp,
        max_depth,
        0..batch_count(spp),
        after_batch,
    )?
    .mean()
}

/// The whole reference from sums of blocks covering every batch (each a node of the tree).
pub fn merge(parts: &[SampleSum]) -> Result<SampleSum> {
    let Some(first) = parts.first() else {
        bail!("no reference parts to merge");
    };
    for p in parts {
        if (p.width, p.height, p.spp) != (first.width, first.height, first.spp) {
            bail!(
                "reference parts of different images: {}×{} at {} spp and {}×{} at {} spp",
                first.width,
                first.height,
                first.spp,
                p.width,
                p.height,
                p.spp
            );
        }
    }
    let all = 0..batch_count(first.spp);
    let texels = tree_sum(all.clone(), &mut |range| {
        Ok(parts
            .iter()
            .find(|p| p.batches == *range)
            .map(|p| p.texels.clone()))
    })
    .context("the parts do not cover the reference's batches as blocks of the summation tree")?;
    Ok(SampleSum {
        width: first.width,
        height: first.height,
        spp: first.spp,
        batches: all,
        texels,
    })
}

const MAGIC: &str = "fovea-sample-sum 1";

#[derive(serde::Serialize, serde::Deserialize)]
struct Header {
    width: u32,
    height: u32,
    spp: u32,
    batches: [u32; 2],
}

/// Writes a sum atomically: a text header line, then the texels as little-endian f64.
pub fn write(path: &Path, sum: &SampleSum) -> Result<()> {
    let header = Header {
        width: sum.width,
        height: sum.height,
        spp: sum.spp,
        batches: [sum.batches.start, sum.batches.end],
    };
    crate::output::write_atomic(path, |w| {
        writeln!(w, "{MAGIC} {}", serde_json::to_string(&header)?)?;
        for t in &sum.texels {
            for c in t {
                w.write_all(&c.to_le_bytes())?;
            }
        }
        Ok(())
    })
}

/// Reads what [`write`] wrote, checking its header and length.
pub fn read(path: &Path) -> Result<SampleSum> {
    crate::output::check_regular_input(path)?;
    let file = std::fs::File::open(path).with_context(|| format!("reading {}", path.display()))?;
    let mut reader = BufReader::new(file);
    let mut line = String::new();
    reader
        .read_line(&mut line)
        .with_context(|| format!("reading {}", path.display()))?;
    let header: Header = line
        .trim_end()
        .strip_prefix(MAGIC)
        .and_then(|h| serde_json::from_str(h.trim()).ok())
        .with_context(|| format!("{}: not a fovea sample sum", path.display()))?;
    let n = header.width as usize * header.height as usize;
    let mut bytes = Vec::new();
    reader
        .read_to_end(&mut bytes)
        .with_context(|| format!("reading {}", path.display()))?;
    if bytes.len() != n * 32 {
        bail!(
            "{}: {} bytes of texels, a {}×{} sum has {}",
            path.display(),
            bytes.len(),
            header.width,
            header.height,
            n * 32
        );
    }
    let texels = bytes
        .chunks_exact(32)
        .map(|t| {
            std::array::from_fn(|c| {
                f64::from_le_bytes(t[c * 8..c * 8 + 8].try_into().expect("8 bytes"))
            })
        })
        .collect();
    let [start, end] = header.batches;
    Ok(SampleSum {
        width: header.width,
        height: header.height,
        spp: header.spp,
        batches: start..end,
        texels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Batch sums whose f64 additions round differently in different orders.
    fn leaf_values(b: u32) -> Texels {
        (0..3)
            .map(|i| {
                let x = 1.0 / (3.0 + b as f64 * 7.0 + i as f64) * 10f64.powi((b % 5) as i32 * 3);
                [x, x * 1e-9, 1e17 / (b as f64 + 1.0), 0.1 * b as f64]
            })
            .collect()
    }

    fn leaves(range: &Range<u32>) -> Result<Option<Texels>> {
        Ok((range.end - range.start == 1).then(|| leaf_values(range.start)))
    }

    #[test]
    fn blocks_of_every_power_of_two_merge_to_the_same_bits() {
        for batches in 1..=37 {
            let whole = tree_sum(0..batches, &mut leaves).unwrap();
            let mut per = 1;
            while per <= 64 {
                let parts: Vec<SampleSum> = blocks(batches, per)
                    .into_iter()
                    .map(|range| SampleSum {
                        width: 3,
                        height: 1,
                        spp: batches * BATCH_SPP,
                        texels: tree_sum(range.clone(), &mut leaves).unwrap(),
                        batches: range,
                    })
                    .collect();
                let merged = merge(&parts).unwrap();
                let bits = |v: &[[f64; 4]]| -> Vec<u64> {
                    v.iter().flatten().map(|x| x.to_bits()).collect()
                };
                assert_eq!(
                    bits(&merged.texels),
                    bits(&whole),
                    "{batches} batches in blocks of {per}"
                );
                per *= 2;
            }
        }
    }

    #[test]
    fn the_order_matters_so_it_is_fixed() {
        // The same leaves summed left to right give other bits for some count: the tree is not
        // a formality.
        let differs = (3..=37).any(|batches| {
            let tree = tree_sum(0..batches, &mut leaves).unwrap();
            let mut seq = leaf_values(0);
            for b in 1..batches {
                for (s, l) in seq.iter_mut().zip(leaf_values(b)) {
                    for c in 0..4 {
                        s[c] += l[c];
                    }
                }
            }
            tree != seq
        });
        assert!(differs);
    }

    #[test]
    fn parts_that_are_not_tree_nodes_are_refused() {
        let part = |range: Range<u32>| SampleSum {
            width: 3,
            height: 1,
            spp: 5 * BATCH_SPP,
            texels: tree_sum(range.clone(), &mut leaves).unwrap(),
            batches: range,
        };
        // 0..3 is not a node of the tree over 0..5 (it splits 0..4 | 4..5).
        let err = merge(&[part(0..3), part(3..5)]).unwrap_err();
        assert!(
            format!("{err:#}").contains("blocks of the summation tree"),
            "{err:#}"
        );
        assert!(merge(&[part(0..4), part(4..5)]).is_ok());
    }

    #[test]
    fn batch_samples_cover_the_reference_once() {
        for spp in [1, 15, 16, 17, 64, 100] {
            let all: Vec<u32> = (0..batch_count(spp))
                .flat_map(|b| batch_samples(spp, b))
                .collect();
            assert_eq!(all, (0..spp).collect::<Vec<_>>());
        }
    }

    #[test]
    fn sums_round_trip_through_their_file() {
        let dir = std::env::temp_dir().join(format!("fovea-sum-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let sum = SampleSum {
            width: 3,
            height: 1,
            spp: 40,
            batches: 2..3,
            texels: leaf_values(7),
        };
        let path = dir.join("sum.bin");
        write(&path, &sum).unwrap();
        assert_eq!(read(&path).unwrap(), sum);
        std::fs::write(&path, b"fovea-sample-sum 1 {\"width\":3}\n").unwrap();
        assert!(format!("{:#}", read(&path).unwrap_err()).contains("not a fovea sample sum"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
