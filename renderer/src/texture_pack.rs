//! Textures as the tracer reads them: every image as a mip chain in one RGBA8 texel array (one
//! u32 per texel), and one [`TextureGpu`] per (image, KHR_texture_transform) pair that a material
//! slot binds, so the shader applies a slot's transform where it reads the texture's extent.
//!
//! Mips are 2×2 box filters (odd sizes round up, the last row/column repeated). Images that a
//! material reads as sRGB colour are averaged in linear light — averaging the encoded values
//! would darken every filtered edge (a black/white checker would mip to 21 % grey, not 50 %).

use crate::layouts::TextureGpu;
use crate::scene::{Scene, Texture, TextureSlot, UvTransform};
use glam::{UVec4, Vec4};
use std::collections::HashMap;

pub struct PackedTextures {
    pub infos: Vec<TextureGpu>,
    pub texels: Vec<u32>,
    /// How many times an image was halved so that all chains fit `max_texels`.
    pub halvings: u32,
    /// Per material, per [`TextureSlot`]: the index into `infos` (None: slot unbound).
    pub material_slots: Vec<[Option<u32>; TextureSlot::COUNT]>,
}

/// Packs `scene`'s textures into at most `max_texels` texels (one storage buffer's range): while
/// the chains exceed it the largest image is halved — a lower-resolution texture beats a
/// descriptor the device cannot bind.
pub fn pack(scene: &Scene, max_texels: usize) -> PackedTextures {
    let srgb = srgb_images(scene);
    let mut level0: Vec<std::borrow::Cow<Texture>> = scene
        .textures
        .iter()
        .map(std::borrow::Cow::Borrowed)
        .collect();
    let total = |ts: &[std::borrow::Cow<Texture>]| {
        ts.iter()
            .map(|t| chain_texels(t.width, t.height))
            .sum::<usize>()
    };
    let mut halvings = 0;
    while total(&level0) > max_texels.max(1) {
        let Some((largest, _)) = level0
            .iter()
            .enumerate()
            .filter(|(_, t)| t.width * t.height > 1)
            .max_by_key(|(_, t)| t.width * t.height)
        else {
            break;
        };
        level0[largest] = std::borrow::Cow::Owned(downsample(&level0[largest], srgb[largest]));
        halvings += 1;
    }
    let mut texels = Vec::with_capacity(total(&level0));
    let mut chains = Vec::with_capacity(level0.len());
    for (image, t) in level0.iter().enumerate() {
        let first = texels.len() as u32;
        let mut levels = 1;
        push_texels(&mut texels, t);
        let mut level = std::borrow::Cow::Borrowed(t.as_ref());
        while level.width > 1 || level.height > 1 {
            level = std::borrow::Cow::Owned(downsample(&level, srgb[image]));
            push_texels(&mut texels, &level);
            levels += 1;
        }
        chains.push(UVec4::new(first, t.width, t.height, levels));
    }
    let (infos, material_slots) = views(scene, &chains);
    PackedTextures {
        infos,
        texels,
        halvings,
        material_slots,
    }
}

/// One [`TextureGpu`] per distinct (image, transform) the materials bind.
fn views(
    scene: &Scene,
    chains: &[UVec4],
) -> (Vec<TextureGpu>, Vec<[Option<u32>; TextureSlot::COUNT]>) {
    let mut infos = Vec::new();
    let mut index: HashMap<(u32, [u32; 5]), u32> = HashMap::new();
    let slots = scene
        .materials
        .iter()
        .map(|m| {
            TextureSlot::ALL.map(|slot| {
                let image = m.texture(slot)?;
                let chain = *chains.get(image as usize)?;
                let transform = m.uv_transforms[slot as usize];
                let key = (image, transform_key(&transform));
                Some(*index.entry(key).or_insert_with(|| {
                    let [u, v] = transform.rows();
                    infos.push(TextureGpu {
                        extent: chain,
                        transform_u: u.extend(0.0),
                        transform_v: v.extend(0.0),
                    });
                    infos.len() as u32 - 1
                }))
            })
        })
        .collect();
    (infos, slots)
}

fn transform_key(t: &UvTransform) -> [u32; 5] {
    [t.offset.x, t.offset.y, t.rotation, t.scale.x, t.scale.y].map(f32::to_bits)
}

/// Whether each image is read as sRGB colour by some material (then its mips average linear
/// light; an image also bound to a linear slot is filtered as colour: glTF gives one meaning per
/// slot, not per image, and colour is where averaging encoded values shows).
fn srgb_images(scene: &Scene) -> Vec<bool> {
    let mut srgb = vec![false; scene.textures.len()];
    for m in &scene.materials {
        for slot in TextureSlot::ALL.into_iter().filter(|s| s.is_srgb()) {
            if let Some(flag) = m.texture(slot).and_then(|i| srgb.get_mut(i as usize)) {
                *flag = true;
            }
        }
    }
    srgb
}

/// Texels of a whole mip chain down to 1×1.
pub fn chain_texels(mut width: u32, mut height: u32) -> usize {
    let mut sum = (width * height) as usize;
    while width > 1 || height > 1 {
        (width, height) = (half(width), half(height));
        sum += (width * height) as usize;
    }
    sum
}

/// The next mip level's size along one axis (the shader's `max((size + 1) >> 1, 1)`).
fn half(size: u32) -> u32 {
    size.div_ceil(2).max(1)
}

fn push_texels(texels: &mut Vec<u32>, t: &Texture) {
    texels.extend(
        t.rgba8
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])),
    );
}

/// `t` at the next mip level: each texel the mean of its 2×2 block (colour in linear light when
/// `srgb`; alpha always linear).
pub fn downsample(t: &Texture, srgb: bool) -> Texture {
    let (w, h) = (half(t.width), half(t.height));
    let decode = srgb_decode_table();
    let at = |x: u32, y: u32| {
        let i = ((y.min(t.height - 1) * t.width + x.min(t.width - 1)) * 4) as usize;
        let c = &t.rgba8[i..i + 4];
        let channel = |k: usize| {
            if srgb && k < 3 {
                decode[c[k] as usize]
            } else {
                c[k] as f32 / 255.0
            }
        };
        Vec4::new(channel(0), channel(1), channel(2), channel(3))
    };
    let mut rgba8 = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let mean = (at(2 * x, 2 * y)
                + at(2 * x + 1, 2 * y)
                + at(2 * x, 2 * y + 1)
                + at(2 * x + 1, 2 * y + 1))
                * 0.25;
            for k in 0..4 {
                rgba8.push(if srgb && k < 3 {
                    srgb_encode(mean[k], &decode)
                } else {
                    (mean[k] * 255.0).round() as u8
                });
            }
        }
    }
    Texture {
        width: w,
        height: h,
        rgba8,
    }
}

/// Linear value of each 8-bit sRGB code (the shader's `srgb_to_linear`).
fn srgb_decode_table() -> [f32; 256] {
    std::array::from_fn(|i| {
        let c = i as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    })
}

/// The 8-bit sRGB code whose linear value is nearest `linear` (a search of the decode table:
/// exact where a formula and rounding would be off by one near black).
fn srgb_encode(linear: f32, decode: &[f32; 256]) -> u8 {
    let above = decode.partition_point(|&v| v < linear).min(255);
    if above > 0 && (linear - decode[above - 1]) <= (decode[above] - linear) {
        (above - 1) as u8
    } else {
        above as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Material;

    fn checker(size: u32) -> Texture {
        let mut rgba8 = Vec::new();
        for y in 0..size {
            for x in 0..size {
                let v = if (x + y) % 2 == 0 { 255 } else { 0 };
                rgba8.extend([v, v, v, 255]);
            }
        }
        Texture {
            width: size,
            height: size,
            rgba8,
        }
    }

    #[test]
    fn srgb_checker_mips_to_half_linear_light() {
        let mip = downsample(&checker(4), true);
        let decode = srgb_decode_table();
        assert_eq!((mip.width, mip.height), (2, 2));
        // Half the light: code 188 (linear 0.5029), not the encoded mean 128 (linear 0.216).
        assert!(
            (decode[mip.rgba8[0] as usize] - 0.5).abs() < 0.003,
            "{}",
            mip.rgba8[0]
        );
        let linear = downsample(&checker(4), false);
        assert_eq!(linear.rgba8[0], 128);
    }

    #[test]
    fn encode_inverts_decode() {
        let decode = srgb_decode_table();
        for code in 0..=255u8 {
            assert_eq!(srgb_encode(decode[code as usize], &decode), code);
        }
    }

    #[test]
    fn chains_go_down_to_one_texel_rounding_up() {
        assert_eq!(chain_texels(1, 1), 1);
        assert_eq!(chain_texels(4, 4), 16 + 4 + 1);
        // 5×3 → 3×2 → 2×1 → 1×1.
        assert_eq!(chain_texels(5, 3), 15 + 6 + 2 + 1);
        let t = Texture {
            width: 5,
            height: 3,
            rgba8: vec![7; 60],
        };
        let m = downsample(&t, false);
        assert_eq!((m.width, m.height), (3, 2));
        assert!(m.rgba8.iter().all(|&v| v == 7));
    }

    #[test]
    fn pack_lays_chains_end_to_end_and_shares_views() {
        let transformed = UvTransform {
            offset: glam::Vec2::new(0.5, 0.0),
            rotation: 0.0,
            scale: glam::Vec2::splat(2.0),
        };
        let mut a = Material {
            base_color_texture: Some(0),
            emissive_texture: Some(1),
            ..Default::default()
        };
        let b = Material {
            base_color_texture: Some(0),
            ..Default::default()
        };
        let c = Material {
            base_color_texture: Some(0),
            ..Default::default()
        };
        a.uv_transforms[TextureSlot::Emissive as usize] = transformed;
        let mut c = c;
        c.uv_transforms[TextureSlot::BaseColor as usize] = transformed;
        let scene = Scene {
            textures: vec![checker(4), checker(2)],
            materials: vec![a, b, c],
            ..Default::default()
        };
        let packed = pack(&scene, usize::MAX);
        assert_eq!(packed.texels.len(), chain_texels(4, 4) + chain_texels(2, 2));
        assert_eq!(packed.halvings, 0);
        // Image 0 untransformed (materials a and b share it), image 1 transformed, image 0 transformed.
        assert_eq!(packed.infos.len(), 3);
        assert_eq!(packed.material_slots[0][0], packed.material_slots[1][0]);
        assert_ne!(packed.material_slots[2][0], packed.material_slots[0][0]);
        let emissive = packed.infos
            [packed.material_slots[0][TextureSlot::Emissive as usize].unwrap() as usize];
        assert_eq!(
            emissive.extent,
            UVec4::new(chain_texels(4, 4) as u32, 2, 2, 2)
        );
        assert_eq!(emissive.transform_u, glam::Vec4::new(2.0, 0.0, 0.5, 0.0));
        assert_eq!(packed.infos[0].extent, UVec4::new(0, 4, 4, 3));
    }

    #[test]
    fn pack_halves_the_largest_until_the_chains_fit() {
        let scene = Scene {
            textures: vec![checker(8), checker(2)],
            materials: vec![Material {
                base_color_texture: Some(0),
                ..Default::default()
            }],
            ..Default::default()
        };
        let packed = pack(&scene, chain_texels(4, 4) + chain_texels(2, 2));
        assert_eq!(packed.halvings, 1);
        assert_eq!(packed.texels.len(), chain_texels(4, 4) + chain_texels(2, 2));
    }
}
