//! Which BVH traversal the kernels that trace run, chosen per device (`--traversal`).
//!
//! - [`Traversal::CpuDriver`]: the 4-wide tree over texel buffers with a register + shared-memory
//!   stack (`fovea_scene::bvh::wide`), shaped for CPU drivers such as lavapipe, which run 8 lanes
//!   per SIMD batch, execute both sides of every branch and scalarise per-lane storage-buffer reads.
//! - [`Traversal::Gpu`]: the compressed 8-wide tree (`fovea_scene::bvh::compressed`, 80-byte
//!   nodes read as uvec4 from storage buffers), children visited in order of entry distance with a
//!   private-memory stack, shaped for GPUs: fewer bytes per ray and no shared memory, which
//!   limited how many workgroups an NVIDIA SM keeps resident.
//!
//! Every kernel that traces is compiled for both (its `+gpu` twin, renderer/build/shaders.rs);
//! the scene upload holds the layout of one ([`crate::gpu_scene::GpuScene::traversal`]).

use ash::vk;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Traversal {
    CpuDriver,
    Gpu,
}

impl Traversal {
    pub const ALL: [Traversal; 2] = [Traversal::CpuDriver, Traversal::Gpu];

    pub fn name(self) -> &'static str {
        match self {
            Traversal::CpuDriver => "cpu-driver",
            Traversal::Gpu => "gpu",
        }
    }

    /// The kernel `shader` compiled for this traversal: the GPU traversal's twin where the kernel
    /// traces rays (`NAME+gpu`), else `shader` itself.
    pub fn shader_name(self, shader: &str) -> std::borrow::Cow<'_, str> {
        match self {
            Traversal::Gpu => {
                let twin = format!("{shader}{GPU_TRAVERSAL_SUFFIX}");
                if crate::shaders::spirv(&twin).is_ok() {
                    twin.into()
                } else {
                    shader.into()
                }
            }
            Traversal::CpuDriver => shader.into(),
        }
    }
}

/// The suffix of a kernel's GPU-traversal twin (renderer/build/shaders.rs).
pub const GPU_TRAVERSAL_SUFFIX: &str = "+gpu";

/// `--traversal`: `auto` picks by the device's type.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TraversalChoice {
    #[default]
    Auto,
    Forced(Traversal),
}

impl TraversalChoice {
    pub fn resolve(self, device_type: vk::PhysicalDeviceType) -> Traversal {
        match self {
            TraversalChoice::Forced(t) => t,
            // A GPU (discrete, integrated or virtualised) gets the GPU traversal; a CPU driver
            // (lavapipe, SwiftShader) and devices of unknown type the CPU driver's.
            TraversalChoice::Auto => match device_type {
                vk::PhysicalDeviceType::DISCRETE_GPU
                | vk::PhysicalDeviceType::INTEGRATED_GPU
                | vk::PhysicalDeviceType::VIRTUAL_GPU => Traversal::Gpu,
                _ => Traversal::CpuDriver,
            },
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            TraversalChoice::Auto => "auto",
            TraversalChoice::Forced(t) => t.name(),
        }
    }
}

impl std::str::FromStr for TraversalChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<TraversalChoice, String> {
        match s {
            "auto" => Ok(TraversalChoice::Auto),
            "cpu-driver" => Ok(TraversalChoice::Forced(Traversal::CpuDriver)),
            "gpu" => Ok(TraversalChoice::Forced(Traversal::Gpu)),
            other => Err(format!(
                "unknown traversal '{other}': auto, cpu-driver or gpu"
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_picks_by_device_type_and_names_parse() {
        let auto = TraversalChoice::Auto;
        assert_eq!(
            auto.resolve(vk::PhysicalDeviceType::DISCRETE_GPU),
            Traversal::Gpu
        );
        assert_eq!(
            auto.resolve(vk::PhysicalDeviceType::INTEGRATED_GPU),
            Traversal::Gpu
        );
        assert_eq!(
            auto.resolve(vk::PhysicalDeviceType::CPU),
            Traversal::CpuDriver
        );
        let forced: TraversalChoice = "cpu-driver".parse().unwrap();
        assert_eq!(
            forced.resolve(vk::PhysicalDeviceType::DISCRETE_GPU),
            Traversal::CpuDriver
        );
        assert_eq!(
            "gpu".parse::<TraversalChoice>().unwrap(),
            TraversalChoice::Forced(Traversal::Gpu)
        );
        assert!("fast".parse::<TraversalChoice>().is_err());
    }

    /// Every kernel that traces has its GPU twin; kernels that do not trace map to themselves.
    #[test]
    fn tracing_kernels_have_gpu_twins() {
        for kernel in [
            "passes/raycast.hits",
            "passes/raycast.counters",
            "passes/trace.cartesian",
        ] {
            assert_eq!(
                Traversal::Gpu.shader_name(kernel),
                format!("{kernel}{GPU_TRAVERSAL_SUFFIX}")
            );
            assert_eq!(Traversal::CpuDriver.shader_name(kernel), kernel);
        }
        assert_eq!(
            Traversal::Gpu.shader_name("passes/tonemap"),
            "passes/tonemap"
        );
    }
}
