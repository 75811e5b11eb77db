//! The GPU's per-texel hash (shaders/common/random.glsl), so the host knows exactly which texels
//! a sparse space traces in a frame (exact sample counts in tests and reports).

pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// `rng_seed` of random.glsl.
pub fn rng_seed(texel: [u32; 2], frame: u32, seed: u32, sample_index: u32) -> u32 {
    pcg_hash(
        texel[0].wrapping_add(pcg_hash(texel[1].wrapping_add(pcg_hash(
            frame.wrapping_add(pcg_hash(seed.wrapping_add(pcg_hash(sample_index)))),
        )))),
    )
}

/// `unit_hash` of random.glsl: uniform in [0, 1), 24 bits.
pub fn unit_hash(texel: [u32; 2], frame: u32, seed: u32, salt: u32) -> f32 {
    (rng_seed(texel, frame, seed, salt) >> 8) as f32 * (1.0 / 16_777_216.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_hash_is_uniform_in_the_unit_interval() {
        let n = 40_000;
        let values: Vec<f32> = (0..n)
            .map(|i| unit_hash([i % 200, i / 200], 3, 7, 11))
            .collect();
        assert!(values.iter().all(|v| (0.0..1.0).contains(v)));
        let mean = values.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
        // Another frame draws anew.
        let same = (0..n)
            .filter(|&i| unit_hash([i % 200, i / 200], 4, 7, 11) == values[i as usize])
            .count();
        assert!(same < 10, "{same}");
    }
}
