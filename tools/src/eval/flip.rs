//! FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images") through
//! NVIDIA's reference implementation: a per-pixel perceptual error in [0, 1] between two sRGB
//! images as seen at a given number of pixels per degree.

/// Per-pixel FLIP error of `test` against `reference` (RGBA8 sRGB, alpha ignored), row-major.
pub fn flip_map(
    reference: &[u8],
    test: &[u8],
    width: u32,
    height: u32,
    pixels_per_degree: f32,
) -> Vec<f64> {
    let rgb = |rgba: &[u8]| {
        rgba.chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect::<Vec<u8>>()
    };
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference));
    let test = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(test));
    nv_flip::flip(reference, test, pixels_per_degree)
        .to_vec()
        .into_iter()
        .map(f64::from)
        .collect()
}

/// FLIP's viewing condition for a render shown on a headset eye: its width over the eye's
/// horizontal FOV, in pixels per degree.
pub fn headset_ppd(hmd: &fovea_hal::HmdDescription, width: u32) -> f32 {
    let fov = hmd.eye(fovea_hal::Eye::Left).fov;
    width as f32 / (fov.angle_right - fov.angle_left).to_degrees().max(1.0)
}

/// A FLIP map as an image (NVIDIA's magma colour map), RGBA8.
pub fn flip_image(map: &[f64], width: u32, height: u32) -> Vec<u8> {
    let values: Vec<f32> = map.iter().map(|&v| v as f32).collect();
    let coloured = nv_flip::FlipImageFloat::with_data(width, height, &values)
        .apply_color_lut(&nv_flip::magma_lut());
    coloured
        .to_vec()
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_have_no_error_and_opposite_ones_a_large_one() {
        let black = [0u8, 0, 0, 255].repeat(16 * 16);
        let white = [255u8, 255, 255, 255].repeat(16 * 16);
        assert!(flip_map(&black, &black, 16, 16, 20.0)
            .iter()
            .all(|&e| e == 0.0));
        let mean = flip_map(&black, &white, 16, 16, 20.0).iter().sum::<f64>() / 256.0;
        assert!(mean > 0.8, "{mean}");
        assert_eq!(flip_image(&[0.5; 4], 2, 2).len(), 16);
    }
}
