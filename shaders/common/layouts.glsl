// The one source of truth for every struct and constant shared by Rust and GLSL.
// build.rs (renderer/build/layouts.rs) parses this file and generates the Rust side; a device
// test reads every field back through this layout. Allowed: `const` scalars and `struct`s of
// float/int/uint, vec2/vec4 (and i/u variants) and mat4. No vec3, no implicit padding.
#ifndef FOVEA_LAYOUTS_GLSL
#define FOVEA_LAYOUTS_GLSL

// Local size of every 2-D image pass (8×8: 64 lanes beat 256 on lavapipe, build-notes.md).
const uint WORKGROUP_2D = 8u;
// Local size of 1-D passes over ray or sample lists.
const uint WORKGROUP_1D = 64u;

const uint NO_TEXTURE = 0xffffffffu;
const uint MATERIAL_DOUBLE_SIDED = 1u;
// alphaMode MASK: MaterialGpu.textures2.w holds the cutoff's float bits.
const uint MATERIAL_ALPHA_MASK = 2u;
// alphaMode BLEND as stochastic transparency: a hit counts with probability alpha.
const uint MATERIAL_ALPHA_BLEND = 4u;

const uint LIGHT_KIND_TRIANGLE = 0u;
const uint LIGHT_KIND_POINT = 1u;
const uint LIGHT_KIND_SPOT = 2u;
const uint LIGHT_KIND_DIRECTIONAL = 3u;
// The environment map (FrameData.environment*): sampled by shaders/common/environment.glsl.
const uint LIGHT_KIND_ENVIRONMENT = 4u;

// FrameData.frame.w flags.
const uint FRAME_FLAG_REFERENCE = 1u;
// The tracer jitters every sample by FrameData.jitter (TAA's Halton sequence) instead of its RNG;
// the RNG stream itself is drawn unchanged, so everything after the jitter stays the same.
const uint FRAME_FLAG_HALTON_JITTER = 2u;
// The scene has alpha-masked or blended materials: traversal tests each candidate hit's alpha
// (without the flag it costs nothing).
const uint FRAME_FLAG_ALPHA_MASK = 4u;
// Texture lookups take a level of detail from each ray's cone (primary spread = the sample's
// footprint on the screen); without the flag every lookup reads mip level 0 (point sampling,
// what references use: jittered samples then converge to the box-filtered pixel).
const uint FRAME_FLAG_TEXTURE_LOD = 8u;
// Samples whose screen position lies farther off the screen than the way back and the filters
// read (trace.comp, OFFSCREEN_CULL_*) are not traced: they hold no sample, like clipped texels.
const uint FRAME_FLAG_CULL_OFFSCREEN = 16u;
// The path's random numbers after the primary hit come from the hit's world position quantised
// at the sample's footprint (random.glsl, surface_rng_seed; StereoNoise::Surface): samples of
// both eyes that land in one cell draw one path. Never set for references.
const uint FRAME_FLAG_SURFACE_NOISE = 32u;
// Salt of the surface seed, apart from the screen seed's streams.
const uint SURFACE_NOISE_SALT = 0x73757266u;

// Salts of unit_hash (random.glsl) for the sparse spaces' choices, apart from the paths' streams:
// whether linear falloff keeps a pixel, where a random-acuity sample lies.
const uint SPARSE_SALT_KEEP = 0x6b656570u;
const uint SPARSE_SALT_POSITION = 0x706f7369u;
// Draws a random-acuity texel makes before it gives up (each rejects a clipped texel; VP clips
// 12 % of the grid by default, so all eight miss about once in 2·10⁷ texels).
const uint RANDOM_ACUITY_TRIES = 8u;
// The splat's fixed point (passes/splat.comp): radiance × this, summed with integer atomics;
// one sample adds at most SPLAT_MAX_RADIANCE (16 of them fill 32 bits).
const float SPLAT_FIXED_POINT = 16384.0;
const float SPLAT_MAX_RADIANCE = 16384.0;

// Everything the passes need to know about the current (and previous) frame.
struct FrameData {
    mat4 world_from_view;       // camera: +X right, +Y up, −Z forward (glTF/OpenXR view axes)
    mat4 prev_view_from_world;  // previous frame's camera, for the previous screen position
    vec4 fov_tan;               // tangents of the left, right, down, up half-angles (left/down < 0)
    vec4 prev_fov_tan;          // the same for the previous frame
    vec4 screen;                // xy screen size in pixels, zw = 1/size
    uvec4 frame;                // x frame index, y seed, z max path depth, w FRAME_FLAG_* bits
    uvec4 counts;               // x light entries, y triangles, z materials, w textures
    vec4 scene_sphere;          // xyz centre, w radius of the scene's bounding sphere
    vec4 jitter;                // xy sub-texel sample offset in [0, 1)² (FRAME_FLAG_HALTON_JITTER), zw unused
    vec4 environment;           // what escaping rays see (Scene::environment_map): x cos, y sin of the map's rotation about +Y, z radiance scale, w probability that light selection picks it (0: not sampled)
    uvec4 environment_map;      // x width, y height (texels), z 1 when there is an environment (0: escaping rays see black), w unused
    vec4 path;                  // x path regularisation strength (RenderSettings::path_regularisation; 0: off), y footprints per surface-noise cell (RenderSettings::surface_cell), z BRDF candidates of ReSTIR DI's reservoirs (ResamplingSettings::brdf_candidates; 0 with resampling off or no emissive triangle in the light table), w unused
    uvec4 instancing;           // x instances (0: none, the instance level is skipped), y flattened triangles (placed ids below are theirs), z top-level root node, w first bvh_triangles texel of its leaf entries
};

// One texel of the environment map with its alias-table slot (environment::EnvironmentDistribution).
struct EnvTexelGpu {
    vec4 radiance;              // rgb linear radiance (before FrameData.environment.z), w probability of choosing this texel
    uvec4 alias;                // x alias texel, y threshold (float bits): keep this texel when u < threshold, zw unused
};

// Push constants of the environment probe (device test of Rust vs GLSL mapping and sampling).
struct EnvProbePush {
    vec4 environment;           // as FrameData.environment
    uvec4 environment_map;      // as FrameData.environment_map
    uvec4 config;               // x point count, yzw unused
};

// Push constants of the BRDF sampling probe (device χ² test of brdf.glsl's sampler).
struct BrdfProbePush {
    vec4 base_color_metallic;   // xyz base colour, w metallic
    vec4 f0_specular;           // xyz dielectric F0, w specular factor
    vec4 view_roughness;        // xyz unit direction toward the viewer, w roughness
    vec4 normal;                // xyz unit shading and geometric normal
    uvec4 config;               // x sample count, yzw unused
};

// Where samples lie on the screen; each sampling space gives the slots its own meaning.
// Visual-Polar packing (VisualPolar::sampling_params, unpacked by vp_unpack): shape1.y = flags
// (1 exact inverse CDF, 2 screen-clipped layout, 4 headset eccentricity axis); paper axis: gaze.zw
// = (r_max, k), shape0 = (u_f, p_f, r_f, e_norm), shape1 = (cdf_max, flags, fovea°, 0); headset
// axis: gaze.zw = (gaze tangent x, k), shape0 = (u_f, p_f, fovea°, gaze tangent y), shape1 =
// (e_max, flags, tangent per pixel x, y). Cartesian: zero. Linear falloff
// (sampling/linear_falloff.glsl): gaze.zw = (inner, outer radius px), shape0 = (floor probability,
// budget scale, 0, 0).
struct SamplingParams {
    uvec4 grid;                 // xy sampling-grid size in texels, zw screen size in pixels
    vec4 gaze;                  // xy gaze in screen pixels, zw space-specific (see above)
    vec4 shape0;                // space-specific parameters
    vec4 shape1;
};

// The gaze-dependent slots of a frame's SamplingParams: what a pass needs of the previous frame's
// space (the grid and screen never change for one renderer), so this frame's space and the
// previous frame's fit in Vulkan's guaranteed 128 push-constant bytes.
struct SamplingFrame {
    vec4 gaze;
    vec4 shape0;
    vec4 shape1;
};

struct MaterialGpu {
    vec4 base_color;            // linear RGBA factor
    vec4 emissive;              // rgb = emissiveFactor × emissive strength, w unused
    vec4 specular;              // rgb = KHR_materials_specular colour factor, w = specular factor
    vec4 surface;               // x metallic, y roughness, z ior, w normal-map scale
    uvec4 textures;             // base colour, metallic-roughness, normal, emissive (NO_TEXTURE = none)
    uvec4 textures2;            // specular (alpha channel), specular colour, MATERIAL_* flags, alpha cutoff (float bits, MATERIAL_ALPHA_MASK)
};

// One texture as a material slot sees it: an image's mip chain in the texel array and the slot's
// KHR_texture_transform (identity when none). Level l+1 is max(1, ceil(size_l / 2)) per axis and
// follows level l in the array.
struct TextureGpu {
    uvec4 extent;               // x first texel of level 0, y width, z height, w mip levels (≥ 1)
    vec4 transform_u;           // u' = dot(xy, uv) + z, w unused
    vec4 transform_v;           // v' = dot(xy, uv) + z, w unused
};

struct VertexGpu {
    vec4 position_u;            // world position, w = texture u
    vec4 normal_v;              // world normal, w = texture v
    vec4 tangent;               // world tangent, w = handedness
};

struct TriangleGpu {
    uvec4 vertices;             // xyz vertex indices, w = material | mesh << 16
};

// One placement of an instanced mesh (fovea_scene::instancing): the 3×4 transforms both ways as
// rows, and where its mesh lives. Placed id first_id + k is the mesh's triangle k.
struct InstanceGpu {
    vec4 object_from_world0;    // rows of the inverse (rays into object space; its columns are the normal matrix's rows)
    vec4 object_from_world1;
    vec4 object_from_world2;
    vec4 world_from_object0;    // rows of the node's world matrix
    vec4 world_from_object1;
    vec4 world_from_object2;
    uvec4 mesh;                 // x first placed id, y BLAS root node in bvh_nodes, z TriangleGpu index of the mesh's triangle 0, w 1 when the transform mirrors
};

struct LightGpu {
    uvec4 kind_index;           // x LIGHT_KIND_*, y placed triangle id or punctual light index, z alias slot, w unused
    vec4 position;              // point/spot position, w = range (0: unlimited)
    vec4 direction;             // direction the light travels (spot, directional), w = cos(outer cone)
    vec4 intensity;             // rgb intensity (cd) or illuminance (lux), w = cos(inner cone)
    vec4 sampling;              // x alias threshold, y probability of choosing this entry, zw unused
};

// Push constants of the trace pass.
struct TracePush {
    uvec4 config;               // x sample index within the frame (reference accumulation), y 0 (the cameras' column base, see trace.comp), zw unused
};

// Push constants of the trace's clearing kernel (passes/trace_clear.comp).
struct TraceClearPush {
    uvec4 config;               // x first idle tile in the tile list, y samples culled in the idle tiles (added to ray counter 4), zw unused
};

// Push constants of the accumulate pass.
struct AccumulatePush {
    uvec4 config;               // x number of samples already in the accumulator, y 1: untraced samples (alpha 0) leave the mean as it is
};

// Push constants of the push-pull fill (passes/fill.comp).
struct FillPush {
    uvec4 config;               // x 0: pull (fine → coarse), 1: push (coarse under fine); yzw unused
};

// Push constants of the splat (passes/splat.comp).
struct SplatPush {
    uvec4 config;               // x 0: scatter the grid's samples into the sums, 1: resolve the sums into the sparse screen image; yzw unused
};

// Push constants of the tonemap pass. The exposure comes from the frame's ExposureState.
struct TonemapPush {
    uvec4 config;               // x operator (TONEMAP_*), yz target offset (px), w unused
};

// Automatic exposure (passes/exposure_meter.comp, passes/exposure_adapt.comp): one histogram of
// log2 luminance over every view's screen radiance, each pixel weighted toward the gaze, and one
// exposure adapted over time from it, which every view's tone mapping reads.
const uint EXPOSURE_BINS = 512u;
const float EXPOSURE_LOG2_MIN = -16.0;
const float EXPOSURE_LOG2_MAX = 16.0;
// A pixel's histogram weight in fixed point: this at the periphery, (1 + boost) times it at the
// gaze.
const float EXPOSURE_WEIGHT_SCALE = 16.0;

// The exposure the tone mapping applies, and the adaptation's state (one per renderer; each
// frame's copy is read back into its slot).
struct ExposureState {
    vec4 values;                // x exposure multiplier applied this frame, y its log2, z this frame's metered target (log2),
                                //   w frames metered so far (0: none, the first metered frame takes its target at once)
};

// Push constants of the exposure meter (one dispatch per view).
struct ExposureMeterPush {
    vec4 gaze;                  // xy gaze (pixels), z 1 / (metering radius in pixels), w extra weight at the gaze (0: flat)
    uvec4 config;               // x block size (pixels per axis; each block's mean over 4×4 taps is one histogram entry), yzw unused
};

// Push constants of the exposure adaptation (one invocation per frame, after every view's meter).
struct ExposureAdaptPush {
    vec4 params;                // x 1 automatic, 0 manual; y the manual multiplier; z compensation (EV, automatic);
                                //   w seconds since the last frame
    vec4 adapt;                 // x time constant toward a brighter scene (s), y toward a darker one (s), z, w the share of
                                //   the histogram's weight left out below and above (the mean is over the rest)
    vec4 limits;                // x lowest, y highest log2 exposure, z log2 of the key (the displayed mean luminance), w unused
};

// Push constants of the raycast pass (BVH tests and ray-throughput benchmarks).
struct RaycastPush {
    uvec4 config;               // x ray count, y any-hit (shadow) mode, zw unused
};

// One ray for the raycast pass.
struct RayGpu {
    vec4 origin_tmin;
    vec4 direction_tmax;
};

// One hit from the raycast pass.
struct HitGpu {
    vec4 t_u_v;                 // t (negative: miss), barycentrics u, v, unused
    uvec4 triangle;             // x original triangle index (0xffffffff: miss), yzw unused
};

// Deepest φ-only mip level of a Visual-Polar image (level 0 is the traced image itself). The φ
// footprint of a screen pixel stays below 2^3 rows except right at the gaze, so 8 is ample.
const uint PHI_MIP_LEVELS = 8u;
// Largest foveated-blur kernel radius in pixels: 3σ of the far periphery (σ ≈ 21 px at 80° on
// a 1280×1440 eye). Taps are spaced with σ, so the cost does not grow with it.
const uint BLUR_MAX_RADIUS = 64u;

// Push constants of the φ-only mip pass: builds level config.x + 1 from level config.x.
// The VP parameters travel as push constants, not through the `sampling` buffer: lavapipe
// turns per-lane storage-buffer reads into scalar loads, which cost these light passes more than
// their arithmetic.
struct MipPhiPush {
    SamplingParams space;       // VisualPolar::sampling_params
    uvec4 config;               // x source level (0 = the VP image), yzw unused
};

// Push constants of the remap-to-screen pass.
struct RemapPush {
    SamplingParams space;       // VisualPolar::sampling_params
    uvec4 config;               // x φ mip levels built (≥ 2), yzw unused
    vec4 sample_offset;         // xy where this frame's samples sit in their VP texel minus ½ (screen-space TAA's
                                //   Halton jitter; 0 otherwise: samples are read as if centred), zw unused
};

// Push constants of the foveated blur (one pass per axis).
struct BlurPush {
    vec4 shape;                 // xy gaze (pixels), z fovea radius (pixels), w σ per pixel beyond it
    uvec4 config;               // x axis (0 horizontal, 1 vertical), y max kernel radius, zw unused
    TonemapPush tone;           // the `ldr` variants (last axis writing the display image): operator, target offset
};

// Push constants of the foveated blur in the Visual-Polar grid (one pass per axis; the axis is
// the kernel variant, phi_* or rho_*).
struct GridBlurPush {
    SamplingParams space;       // VisualPolar::sampling_params (the paper's layout)
    vec4 shape;                 // as BlurPush.shape: xy gaze, z blur start (pixels), w σ per pixel beyond it
};

// Push constants of the Visual-Polar mapping probe (device test of Rust vs GLSL).
struct VpProbePush {
    uvec4 config;               // x point count, yzw unused
};

// ---- Denoisers: they run in the sampling grid (texel = sample). Every pass gets the
// space as SamplingParams push constants (see MipPhiPush for why not the buffer); Cartesian
// kernel variants ignore it.

// Luminance ceiling of a sample entering SVGF's history: a firefly may not make the squared
// moment overflow (demodulated light sources stay far below it).
const float SVGF_MAX_LUMINANCE = 65504.0;

// Push constants of SVGF's temporal accumulation (128 bytes: see SamplingFrame).
struct SvgfTemporalPush {
    SamplingParams space;       // this frame's space
    SamplingFrame prev;         // the previous frame's (its grid = space.grid)
    vec4 params;                // x α colour, y α moments, z history cap (frames), w 1 = drop all history
};

// Push constants of SVGF's variance estimate (spatial 7×7 while the history is short).
struct SvgfVariancePush {
    SamplingParams space;
    vec4 params;                // x σ luminance, y σ depth, z σ normal, w history (frames) below which it is spatial
};

// Push constants of one SVGF à-trous iteration.
struct SvgfAtrousPush {
    SamplingParams space;
    vec4 params;                // x σ luminance, y σ depth, z σ normal, w unused
    uvec4 config;               // x tap spacing (2^iteration texels), yzw unused
};

// Push constants of SVGF's state in the trace's idle tiles (svgf_idle.comp).
struct SvgfIdlePush {
    SamplingParams space;
    uvec4 config;               // x first idle tile in the tile list, yzw unused
};

// Push constants of TAA in the sampling grid (Karis 2014), 128 bytes like SvgfTemporalPush.
struct TaaPush {
    SamplingParams space;       // this frame's space
    SamplingFrame prev;         // the previous frame's (its grid = space.grid)
    vec4 params;                // x current-frame weight, y 1 = drop all history, zw this frame's jitter in the texel
};

// Push constants of TAA after the remap to screen space (beyond the paper, its future work). The
// VP samples jitter by a Halton offset inside their VP texel, so on the screen the jitter spans one
// texel footprint: under a pixel from the fovea, many pixels in the periphery. The pass reads the
// footprint from the space to size its neighbourhood.
struct TaaScreenPush {
    SamplingParams space;       // this frame's space
    vec4 params;                // x current-frame weight, y 1 = drop all history, zw unused
};

// ---- BMFR (Koskela et al. 2019, TOG): blockwise multi-order feature regression.

// Side of a fit block in texels: a block is BMFR_BLOCK² = 1024 rows of the least-squares matrix.
const uint BMFR_BLOCK = 32u;
// Features per row: 1, normal xyz, position xyz, position² xyz.
const uint BMFR_FEATURES = 10u;
// Lanes of one fit workgroup (one workgroup per block; each lane owns 1024 / lanes rows). 64 beats
// 256 on lavapipe by ~4× (every barrier is a pass over all lanes there).
const uint BMFR_FIT_LANES = 64u;
// Texels per block in the weights image: 10 weight texels (rgb per feature), then the position
// scaling (min xyz, 1/range xyz).
const uint BMFR_WEIGHT_TEXELS = 12u;

// Push constants of BMFR's two temporal passes (accumulation of the noisy input and features
// before the fit, of the fitted colour after it), 128 bytes like SvgfTemporalPush.
struct BmfrTemporalPush {
    SamplingParams space;       // this frame's space
    SamplingFrame prev;         // the previous frame's (its grid = space.grid)
    vec4 params;                // xyz previous camera origin − this one (positions are camera-relative), w α floor (1: drop all history)
};

// Push constants of BMFR's per-block fit and of its per-texel weighted sum.
struct BmfrBlockPush {
    SamplingParams space;
    ivec4 config;               // xy block-grid offset (texels, in [−16, 14]), z noise seed (frame), w unused
    vec4 params;                // x stochastic regularisation amplitude, yzw unused
};

// Push constants of BMFR's state in the trace's idle tiles (bmfr_idle.comp).
struct BmfrIdlePush {
    SamplingParams space;
    uvec4 config;               // x first idle tile in the tile list, yzw unused
};

// ---- A-SVGF (Schied et al. 2018): gradient samples, one per ASVGF_STRATUM × ASVGF_STRATUM
// stratum of the sampling grid, reconstructed at that 1/3 resolution into the temporal α of SVGF.
const uint ASVGF_STRATUM = 3u;
// AsvgfGradientSample.shading.w until the tracer has re-shaded the sample.
const uint ASVGF_NO_LUMINANCE = 0xffffffffu;

// One stratum's gradient sample: last frame's surface and random state, forward-projected into
// this frame's grid (asvgf_forward.comp), and the luminance of both shadings (demodulated).
struct AsvgfGradientSample {
    uvec4 surface;              // x 1 + last frame's texel index (0: none claimed this stratum), y triangle + 1, zw barycentrics (float bits)
    uvec4 shading;              // x this frame's texel (x | y << 16), y RNG state after the jitter draw, z last luminance, w this frame's (float bits; ASVGF_NO_LUMINANCE: not re-shaded)
};

// Push constants of A-SVGF's forward projection (one invocation per stratum of last frame).
struct AsvgfForwardPush {
    SamplingParams space;       // this frame's space
    uvec4 config;               // x 1: project last frame's samples, 0: only clear the gradient image (no usable last frame); yzw unused
};

// Push constants of one iteration of A-SVGF's gradient reconstruction (à-trous on the strata).
struct AsvgfGradientPush {
    SamplingParams space;       // this frame's space
    vec4 params;                // x σ depth, y σ normal, zw unused
    uvec4 config;               // x tap spacing in strata (2^iteration), yzw unused
};

// ---- Resampling (ReSTIR DI, Bitterli et al. 2020; docs/design/resampling.md): one reservoir
// of light samples per sampling-grid texel, reused over time and over grid neighbours.

// Salts of the resampling passes' own random streams, rng_seed(texel, frame, seed, salt) (the
// paths' streams use sample indices): candidate generation, and the reuse decisions.
const uint RESAMPLING_SALT_CANDIDATES = 0x72697363u;
const uint RESAMPLING_SALT_REUSE = 0x72657573u;
// ReSTIR GI's passes: the temporal decision, and the spatial pass's neighbours and decisions.
const uint RESAMPLING_SALT_GI_TEMPORAL = 0x67697465u;
const uint RESAMPLING_SALT_GI_REUSE = 0x67697275u;
// Most grid neighbours the spatial pass combines per sample (it keeps their taps for the
// normalisation).
const uint RESAMPLING_MAX_NEIGHBOURS = 16u;

// One texel's reservoir: the chosen light sample, its weights and the surface it belongs to.
// The sample is a point of the light table that re-evaluates exactly anywhere (no Jacobian):
// an emissive triangle's point by barycentrics, the environment's direction (octahedral),
// a punctual or directional light by its entry alone.
struct ReservoirGpu {
    uvec4 light_point;          // x light entry + 1 (0: empty), y, z the point (float bits: barycentrics u, v, or the
                                //   environment direction's octahedral x, y), w unused
    vec4 weights;               // x W (unbiased contribution weight), y M (candidates it stands for), z p̂ of the sample at
                                //   its own surface, w unused
    uvec4 surface;              // the owner's surface (denoise/svgf.glsl svgf_pack_surface; key 0: no sample)
    vec4 position;              // xyz the owner's shading point (world space; W is for its visibility), w unused
};

// The bounce the tracer's `*_resampled_gi` kernel traced from a primary hit (ReSTIR GI's initial
// sample): the secondary hit and the radiance the rest of the path gathered there.
struct GiSampleGpu {
    vec4 point;                 // xyz the secondary hit (world space) or, for a bounce that escaped, its direction; w the
                                //   bounce direction's solid-angle density at the primary hit (0: no sample: a mirror's
                                //   bounce, or the path ended)
    vec4 normal;                // xyz the secondary hit's geometric normal, facing the primary hit (zero: the
                                //   environment); w unused
    vec4 radiance;              // rgb radiance leaving the secondary hit toward the primary hit (its emission excluded:
                                //   next-event estimation at the primary hit counts that), or the environment's; a unused
};

// One texel's ReSTIR GI reservoir: the chosen secondary hit with its radiance, its weights and the
// surface (primary hit) it belongs to. Reused at another primary hit by reconnection: the
// secondary hit stays, the direction to it changes (a Jacobian converts the densities).
struct GiReservoirGpu {
    vec4 point;                 // xyz the chosen secondary hit (world space; the environment: a direction), w W
                                //   (unbiased contribution weight, per solid angle at the owner)
    vec4 normal;                // xyz its geometric normal (zero: the environment), w M (candidates it stands for)
    vec4 radiance;              // rgb its outgoing radiance, a p̂ of the sample at the owner's surface (0: empty)
    uvec4 surface;              // the owner's surface (denoise/svgf.glsl svgf_pack_surface; key 0: no sample)
    vec4 position;              // xyz the owner's shading point (world space), w unused
};

// Push constants of the first resampling pass (initial candidates, visibility, temporal reuse),
// 128 bytes like SvgfTemporalPush.
struct ResampleTemporalPush {
    SamplingParams space;       // this frame's space
    SamplingFrame prev;         // the previous frame's (its grid = space.grid)
    vec4 params;                // x light candidates per texel (ReSTIR GI: 1, the traced bounce), y M cap of the
                                //   previous reservoir (× this frame's candidates), z 1 = no usable history, w unused
};

// Push constants of the second resampling pass (spatial reuse and the final shading).
struct ResampleSpatialPush {
    SamplingParams space;       // this frame's space
    vec4 params;                // x neighbours, y radius (grid texels), zw unused
};

// Push constants of the cross-eye merge (passes/cross_eye.comp): the other eye's space (its grid
// is this eye's size; its gaze and shape its own).
struct CrossEyePush {
    SamplingParams other;       // the other eye's space this frame
    uvec4 config;               // x 0 (a column index lavapipe cannot fold, see cross_eye.comp), yzw unused
};

const uint TONEMAP_CLAMP = 0u;
const uint TONEMAP_ACES = 1u;
const uint TONEMAP_NEUTRAL = 2u;

#endif
