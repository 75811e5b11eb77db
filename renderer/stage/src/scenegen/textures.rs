//! Procedural textures, PNG-encoded: the near-checkerboards that foveated sampling finds hardest.

use super::shapes::SplitMix64;

/// A `size`² near-checkerboard: squares of `square` texels whose row/column boundaries wander
/// by up to ±1 texel, with a little per-square brightness noise, so the pattern is almost but not
/// exactly periodic (exact periodicity would let aliasing hide as a clean moiré).
pub fn near_checker_png(
    size: u32,
    square: u32,
    dark: [u8; 3],
    light: [u8; 3],
    rng: &mut SplitMix64,
) -> Vec<u8> {
    let jitter = |rng: &mut SplitMix64| -> Vec<u32> {
        // Cumulative boundaries with widths in square−1 ..= square+1.
        let mut edges = vec![0u32];
        while *edges.last().unwrap_or(&0) < size {
            let w = square + (rng.next_u64() % 3) as u32 - 1;
            edges.push(edges.last().unwrap_or(&0) + w.max(1));
        }
        (0..size)
            .map(|x| edges.partition_point(|&e| e <= x) as u32)
            .collect()
    };
    let (column_of, row_of) = (jitter(rng), jitter(rng));
    let squares = column_of.last().copied().unwrap_or(0) as usize + 1;
    let noise: Vec<f32> = (0..squares * (row_of.last().copied().unwrap_or(0) as usize + 1))
        .map(|_| rng.range(0.85, 1.0))
        .collect();
    let mut pixels = Vec::with_capacity((size * size * 3) as usize);
    for &r in &row_of {
        for &c in &column_of {
            let base = if (c + r) % 2 == 0 { dark } else { light };
            let k = noise[r as usize * squares + c as usize];
            pixels.extend(base.map(|v| (v as f32 * k).round() as u8));
        }
    }
    encode_rgb_png(size, size, pixels)
}

/// Thin horizontal and vertical lines (1 texel wide every `period` texels) on a plain ground:
/// the other classic high-frequency case (text, tiles, fences at a distance).
pub fn fine_grid_png(size: u32, period: u32, ground: [u8; 3], line: [u8; 3]) -> Vec<u8> {
    let mut pixels = Vec::with_capacity((size * size * 3) as usize);
    for y in 0..size {
        for x in 0..size {
            pixels.extend(if x % period == 0 || y % period == 0 {
                line
            } else {
                ground
            });
        }
    }
    encode_rgb_png(size, size, pixels)
}

fn encode_rgb_png(width: u32, height: u32, pixels: Vec<u8>) -> Vec<u8> {
    let mut png = Vec::new();
    let image =
        image::RgbImage::from_raw(width, height, pixels).expect("pixel count matches the size");
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .expect("PNG encoding into memory cannot fail");
    png
}
