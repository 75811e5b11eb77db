//! Compute pipelines built from the SPIR-V compiled at build time. Bindings, workgroup size and
//! push-constant size are reflected from the SPIR-V (the shader is the one source of truth for
//! binding numbers) and the Rust params struct is checked against the push-constant block.

use super::context::Context;
use crate::error::{Error, Result};
use crate::shaders;
use ash::vk;
use rspirv_reflect::{DescriptorType, Reflection};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct BindingInfo {
    pub name: String,
    pub binding: u32,
    pub ty: vk::DescriptorType,
}

pub struct ComputePipeline {
    ctx: Arc<Context>,
    pub shader: String,
    pub raw: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    pub set_layout: vk::DescriptorSetLayout,
    pub bindings: Vec<BindingInfo>,
    pub local_size: [u32; 3],
    pub push_size: u32,
}

impl ComputePipeline {
    /// Builds the pipeline for `shader` (a name from `shaders::SHADERS`, e.g. "passes/trace.cartesian")
    /// whose push-constant block must be exactly `push_size` bytes (0 for none).
    pub fn new(ctx: &Arc<Context>, shader: &str, push_size: u32) -> Result<ComputePipeline> {
        let bytes = shaders::spirv(shader)?;
        let err = |reason: String| Error::Shader {
            shader: shader.to_string(),
            reason,
        };
        let reflection =
            Reflection::new_from_spirv(bytes).map_err(|e| err(format!("reflection: {e:?}")))?;
        let sets = reflection
            .get_descriptor_sets()
            .map_err(|e| err(format!("reflection: {e:?}")))?;
        if sets.keys().any(|&s| s != 0) {
            return Err(err(
                "only descriptor set 0 is supported (push descriptors)".into()
            ));
        }
        let mut bindings: Vec<BindingInfo> = Vec::new();
        if let Some(set) = sets.get(&0) {
            for (&binding, info) in set {
                bindings.push(BindingInfo {
                    name: info.name.clone(),
                    binding,
                    ty: descriptor_type(info.ty).map_err(err)?,
                });
            }
        }
        let local = reflection
            .get_compute_group_size()
            .ok_or_else(|| err("no workgroup size".into()))?;
        let reflected_push = reflection
            .get_push_constant_range()
            .map_err(|e| err(format!("reflection: {e:?}")))?
            .map_or(0, |p| p.size);
        if reflected_push != push_size {
            return Err(err(format!(
                "push-constant block is {reflected_push} bytes, the Rust params struct {push_size}"
            )));
        }

        let device = &ctx.device;
        let layout_bindings: Vec<vk::DescriptorSetLayoutBinding> = bindings
            .iter()
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b.binding)
                    .descriptor_type(b.ty)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
            })
            .collect();
        let set_info = vk::DescriptorSetLayoutCreateInfo::default()
            .flags(vk::DescriptorSetLayoutCreateFlags::PUSH_DESCRIPTOR_KHR)
            .bindings(&layout_bindings);
        let set_layout = unsafe { device.create_descriptor_set_layout(&set_info, None)? };
        let ranges = [vk::PushConstantRange {
            stage_flags: vk::ShaderStageFlags::COMPUTE,
            offset: 0,
            size: push_size,
        }];
        let set_layouts = [set_layout];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        if push_size > 0 {
            layout_info = layout_info.push_constant_ranges(&ranges);
        }
        let layout = unsafe { device.create_pipeline_layout(&layout_info, None)? };

        let words = ash::util::read_spv(&mut std::io::Cursor::new(bytes))
            .map_err(|e| err(e.to_string()))?;
        let module_info = vk::ShaderModuleCreateInfo::default().code(&words);
        let module = unsafe { device.create_shader_module(&module_info, None)? };
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main");
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout);
        let result =
            unsafe { device.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) };
        unsafe { device.destroy_shader_module(module, None) };
        let raw = result.map_err(|(_, e)| Error::Vulkan(e))?[0];
        ctx.set_name(raw, shader);
        Ok(ComputePipeline {
            ctx: ctx.clone(),
            shader: shader.to_string(),
            raw,
            layout,
            set_layout,
            bindings,
            local_size: [local.0, local.1, local.2],
            push_size,
        })
    }

    /// The one pipeline of `shader` on this context, built on first use and shared by every pass
    /// and view that runs the kernel (stereo views share their pipelines). A kernel that traces
    /// rays runs the context's BVH traversal ([`Context::traversal`]).
    pub fn shared(
        ctx: &Arc<Context>,
        shader: &str,
        push_size: u32,
    ) -> Result<Arc<ComputePipeline>> {
        ComputePipeline::shared_for(ctx, shader, push_size, ctx.traversal)
    }

    /// [`ComputePipeline::shared`] with the kernel compiled for `traversal`.
    pub fn shared_for(
        ctx: &Arc<Context>,
        shader: &str,
        push_size: u32,
        traversal: crate::traversal::Traversal,
    ) -> Result<Arc<ComputePipeline>> {
        let resolved = traversal.shader_name(shader);
        let shader: &str = &resolved;
        let mut cache = ctx.pipelines.lock().expect("pipeline cache lock");
        let cached = cache.get(shader).and_then(|w| w.upgrade());
        if let Some(p) = cached.and_then(|p| p.downcast::<ComputePipeline>().ok()) {
            if p.push_size != push_size {
                return Err(Error::Shader {
                    shader: shader.into(),
                    reason: format!(
                        "push-constant block is {} bytes, the Rust params struct {push_size}",
                        p.push_size
                    ),
                });
            }
            return Ok(p);
        }
        let pipeline = Arc::new(ComputePipeline::new(ctx, shader, push_size)?);
        cache.retain(|_, w| w.strong_count() > 0);
        let entry: Arc<dyn std::any::Any + Send + Sync> = pipeline.clone();
        cache.insert(shader.to_string(), Arc::downgrade(&entry));
        Ok(pipeline)
    }

    /// Workgroups needed to cover `threads` invocations along each axis.
    pub fn groups_for(&self, threads: [u32; 3]) -> [u32; 3] {
        [0, 1, 2].map(|i| threads[i].div_ceil(self.local_size[i]))
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        unsafe {
            self.ctx.device.destroy_pipeline(self.raw, None);
            self.ctx.device.destroy_pipeline_layout(self.layout, None);
            self.ctx
                .device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

fn descriptor_type(ty: DescriptorType) -> std::result::Result<vk::DescriptorType, String> {
    Ok(match ty {
        DescriptorType::STORAGE_BUFFER => vk::DescriptorType::STORAGE_BUFFER,
        DescriptorType::STORAGE_IMAGE => vk::DescriptorType::STORAGE_IMAGE,
        DescriptorType::UNIFORM_TEXEL_BUFFER => vk::DescriptorType::UNIFORM_TEXEL_BUFFER,
        DescriptorType::COMBINED_IMAGE_SAMPLER => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        DescriptorType::UNIFORM_BUFFER => vk::DescriptorType::UNIFORM_BUFFER,
        other => return Err(format!("descriptor type {} not supported", other.0)),
    })
}
