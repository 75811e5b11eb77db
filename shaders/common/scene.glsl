// Scene bindings shared by every pass that traces rays, and the surface record at a hit.
// Binding numbers live only here; the engine binds by name (reflected from SPIR-V).
#ifndef FOVEA_SCENE_GLSL
#define FOVEA_SCENE_GLSL

#include "layouts.glsl"
#include "random.glsl"

#if defined(BVH_TRAVERSAL_GPU)
// The GPU traversal's compressed 8-wide tree: 5 uvec4 per node, 3 vec4 per leaf triangle (bvh.glsl).
layout(std430, set = 0, binding = 0) readonly buffer Bvh8NodeBuffer { uvec4 data[]; } bvh8_nodes;
layout(std430, set = 0, binding = 1) readonly buffer Bvh8TriangleBuffer { vec4 data[]; } bvh8_triangles;
#else
layout(set = 0, binding = 0) uniform samplerBuffer bvh_nodes;
layout(set = 0, binding = 1) uniform samplerBuffer bvh_triangles;
#endif
layout(std430, set = 0, binding = 2) readonly buffer VertexBuffer { VertexGpu data[]; } vertices;
layout(std430, set = 0, binding = 3) readonly buffer TriangleBuffer { TriangleGpu data[]; } triangles;
layout(std430, set = 0, binding = 4) readonly buffer MaterialBuffer { MaterialGpu data[]; } materials;
layout(std430, set = 0, binding = 5) readonly buffer TextureBuffer { TextureGpu data[]; } textures;
layout(std430, set = 0, binding = 6) readonly buffer TexelBuffer { uint data[]; } texels;     // RGBA8
layout(std430, set = 0, binding = 7) readonly buffer LightBuffer { LightGpu data[]; } lights;
#include "frame.glsl"
// Instances in fovea_scene's order (ascending first placed id); a dummy entry when there are none.
layout(std430, set = 0, binding = 25) readonly buffer InstanceBuffer { InstanceGpu data[]; } instances;

// Defined below; bvh.glsl's traversal calls it for scenes with alpha-masked materials.
bool alpha_rejects(uint triangle, uint id, float u, float v);

#include "bvh.glsl"

// A vertex of an instanced mesh in world space, as fovea_scene::Instance::vertex_to_world:
// positions by the matrix, normals by its inverse transpose (the inverse's columns), tangents by
// its 3×3 part with the handedness flipped by a mirror.
VertexGpu instance_vertex(InstanceGpu inst, VertexGpu v) {
    vec4 p = vec4(v.position_u.xyz, 1.0);
    vec3 n = v.normal_v.xyz, t = v.tangent.xyz;
    mat3 linear = mat3(inst.world_from_object0.xyz, inst.world_from_object1.xyz, inst.world_from_object2.xyz); // rows as columns: transposed
    vec3 wn = n.x * inst.object_from_world0.xyz + n.y * inst.object_from_world1.xyz + n.z * inst.object_from_world2.xyz;
    vec3 wt = t * linear;
    VertexGpu w;
    w.position_u = vec4(dot(inst.world_from_object0, p), dot(inst.world_from_object1, p), dot(inst.world_from_object2, p), v.position_u.w);
    w.normal_v = vec4(normalize(wn), v.normal_v.w);
    w.tangent = vec4(normalize(wt), inst.mesh.w != 0u ? -v.tangent.w : v.tangent.w);
    return w;
}

// A placed triangle (fovea_scene::instancing: flattened ids first, then each instance's) in world
// space: its TriangleGpu (material, mesh) and corners. `mirrored`: the corners wind clockwise
// seen from the front (the flattened copy would have swapped two of them).
struct PlacedTriangle {
    TriangleGpu tri;
    VertexGpu a, b, c;
    bool mirrored;
};

PlacedTriangle placed_triangle(uint id) {
    PlacedTriangle p;
    p.mirrored = false;
    if (id < frame.data.instancing.y) {
        p.tri = triangles.data[id];
        p.a = vertices.data[p.tri.vertices.x];
        p.b = vertices.data[p.tri.vertices.y];
        p.c = vertices.data[p.tri.vertices.z];
        return p;
    }
    // The instance with the largest first id ≤ id (instances are in ascending first id).
    uint lo = 0u, hi = frame.data.instancing.x;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) >> 1u;
        if (instances.data[mid].mesh.x <= id) lo = mid; else hi = mid;
    }
    InstanceGpu inst = instances.data[lo];
    p.tri = triangles.data[inst.mesh.z + (id - inst.mesh.x)];
    p.a = instance_vertex(inst, vertices.data[p.tri.vertices.x]);
    p.b = instance_vertex(inst, vertices.data[p.tri.vertices.y]);
    p.c = instance_vertex(inst, vertices.data[p.tri.vertices.z]);
    p.mirrored = inst.mesh.w != 0u;
    return p;
}

vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

vec4 texel_rgba8(uint index) {
    return unpackUnorm4x8(texels.data[index]);
}

// Bilinear, wrap-repeat, in one mip level (`first` texel, `size`); `srgb` decodes before filtering
// (base colour, emissive, specular colour).
vec4 sample_bilinear(uint first, uvec2 size, vec2 uv, bool srgb) {
    vec2 p = uv * vec2(size) - 0.5;
    vec2 f = fract(p);
    ivec2 i0 = ivec2(floor(p));
    vec4 acc = vec4(0.0);
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        uvec2 q = uvec2((i0 + o) % ivec2(size) + ivec2(size)) % size;
        vec4 c = texel_rgba8(first + q.y * size.x + q.x);
        if (srgb) c.rgb = srgb_to_linear(c.rgb);
        float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        acc += w * c;
    }
    return acc;
}

// Texture `tex` at `uv` (before its KHR_texture_transform), trilinear between mip levels.
// `lod_uv` is the footprint's level of detail in uv units, log2(footprint width / uv period);
// the texture adds its own size. −∞ (any value below −1e30) reads level 0.
vec4 sample_texture_lod(uint tex, vec2 uv, bool srgb, float lod_uv) {
    TextureGpu info = textures.data[tex];
    vec2 st = vec2(dot(info.transform_u.xy, uv) + info.transform_u.z, dot(info.transform_v.xy, uv) + info.transform_v.z);
    uvec2 size = info.extent.yz;
    uint first = info.extent.x;
    // The transform scales uv areas by |det|; the footprint in texels by √(w·h·|det|).
    float det = abs(info.transform_u.x * info.transform_v.y - info.transform_u.y * info.transform_v.x);
    float lambda = lod_uv + 0.5 * log2(float(size.x) * float(size.y) * max(det, 1e-30));
    lambda = lod_uv < -1e30 || isnan(lambda) ? 0.0 : clamp(lambda, 0.0, float(info.extent.w - 1u));
    uint level = uint(lambda);
    for (uint l = 0u; l < level; ++l) {
        first += size.x * size.y;
        size = max((size + 1u) >> 1u, uvec2(1u));
    }
    vec4 c = sample_bilinear(first, size, st, srgb);
    float blend = lambda - float(level);
    if (blend > 0.0) c = mix(c, sample_bilinear(first + size.x * size.y, max((size + 1u) >> 1u, uvec2(1u)), st, srgb), blend);
    return c;
}

// Level 0 (point-sampled footprint): alpha tests and emission seen by light sampling.
vec4 sample_texture(uint tex, vec2 uv, bool srgb) {
    return sample_texture_lod(tex, uv, srgb, -1e38);
}

// glTF alphaMode MASK: a hit where base-colour alpha (factor × texture, at the hit's uv) is below
// the material's cutoff is no hit, for camera, bounce and shadow rays alike. BLEND: the hit counts
// with probability alpha (stochastic transparency), decided by a hash of the hit (triangle,
// barycentrics, frame and seed), so every ray and frame draws anew and the mean converges to the
// blend. `triangle` is the TriangleGpu (uv need no transform), `id` the placed id (the hash).
bool alpha_rejects(uint triangle, uint id, float u, float v) {
    TriangleGpu tri = triangles.data[triangle];
    MaterialGpu m = materials.data[tri.vertices.w & 0xffffu];
    if ((m.textures2.z & (MATERIAL_ALPHA_MASK | MATERIAL_ALPHA_BLEND)) == 0u) return false;
    float alpha = m.base_color.a;
    if (m.textures.x != NO_TEXTURE) {
        VertexGpu a = vertices.data[tri.vertices.x];
        VertexGpu b = vertices.data[tri.vertices.y];
        VertexGpu c = vertices.data[tri.vertices.z];
        vec2 uv = (1.0 - u - v) * vec2(a.position_u.w, a.normal_v.w) + u * vec2(b.position_u.w, b.normal_v.w) + v * vec2(c.position_u.w, c.normal_v.w);
        alpha *= sample_texture(m.textures.x, uv, false).a;
    }
    if ((m.textures2.z & MATERIAL_ALPHA_BLEND) != 0u) {
        uint h = pcg_hash(id ^ pcg_hash(floatBitsToUint(u) ^ pcg_hash(floatBitsToUint(v) ^ pcg_hash(frame.data.frame.x ^ pcg_hash(frame.data.frame.y)))));
        return float(h >> 8u) * (1.0 / 16777216.0) >= alpha;
    }
    return alpha < uintBitsToFloat(m.textures2.w);
}

struct Surface {
    vec3 position;
    vec3 geometric_normal;  // faces the incoming ray
    vec3 normal;            // shading normal (normal-mapped), same hemisphere as geometric_normal
    vec2 uv;
    vec3 base_color;
    float metallic;
    float roughness;
    vec3 emission;          // radiance leaving the front face (zero from the back unless double-sided)
    vec3 dielectric_f0;     // F0 × specular colour, KHR_materials_ior/_specular
    float specular_factor;
    uint material;
    uint mesh;
};

// The surface at `hit`, textures filtered for a ray cone `cone_width` wide there (world units
// across the ray; ≤ 0: level 0). Level of detail after Akenine-Möller et al. 2019 (Ray Tracing
// Gems ch. 20): λ = ½ log2(uv area / world area) + log2(width) − log2|n·d|, plus the texture's
// ½ log2(w·h) in sample_texture_lod.
Surface fetch_surface(Hit hit, vec3 ray_dir, float cone_width) {
    PlacedTriangle placed = placed_triangle(hit.triangle);
    TriangleGpu tri = placed.tri;
    VertexGpu a = placed.a, b = placed.b, c = placed.c;
    vec3 w = vec3(1.0 - hit.u - hit.v, hit.u, hit.v);
    Surface s;
    s.material = tri.vertices.w & 0xffffu;
    s.mesh = tri.vertices.w >> 16u;
    s.position = w.x * a.position_u.xyz + w.y * b.position_u.xyz + w.z * c.position_u.xyz;
    s.uv = w.x * vec2(a.position_u.w, a.normal_v.w) + w.y * vec2(b.position_u.w, b.normal_v.w) + w.z * vec2(c.position_u.w, c.normal_v.w);
    vec3 ng = normalize(cross(b.position_u.xyz - a.position_u.xyz, c.position_u.xyz - a.position_u.xyz));
    if (placed.mirrored) ng = -ng;
    bool front = dot(ng, ray_dir) < 0.0;
    vec3 n = normalize(w.x * a.normal_v.xyz + w.y * b.normal_v.xyz + w.z * c.normal_v.xyz);

    MaterialGpu m = materials.data[s.material];
    float lod_uv = -1e38;
    if (cone_width > 0.0) {
        vec2 uv_a = vec2(a.position_u.w, a.normal_v.w), uv_b = vec2(b.position_u.w, b.normal_v.w), uv_c = vec2(c.position_u.w, c.normal_v.w);
        vec2 e1 = uv_b - uv_a, e2 = uv_c - uv_a;
        float uv_area = abs(e1.x * e2.y - e1.y * e2.x);
        float world_area = length(cross(b.position_u.xyz - a.position_u.xyz, c.position_u.xyz - a.position_u.xyz));
        lod_uv = 0.5 * log2(uv_area / world_area) + log2(cone_width) - log2(max(abs(dot(ng, ray_dir)), 1e-4));
    }
    // All texture lookups go through ONE sample_texture in a loop over the lane's bound slots:
    // lavapipe executes both sides of every branch under a lane mask, so six guarded calls cost six
    // full lookups per hit even for untextured materials; the loop costs max(bound slots, 1).
    // Slots: 0 base colour, 1 metallic-roughness, 2 normal, 3 emissive, 4 specular, 5 specular colour.
    uvec3 tex_lo = m.textures.xyz;
    uint tex_emissive = m.textures.w;
    uvec2 tex_hi = m.textures2.xy;
    uint pending = (tex_lo.x != NO_TEXTURE ? 1u : 0u) | (tex_lo.y != NO_TEXTURE ? 2u : 0u)
        | (tex_lo.z != NO_TEXTURE ? 4u : 0u) | (tex_emissive != NO_TEXTURE ? 8u : 0u)
        | (tex_hi.x != NO_TEXTURE ? 16u : 0u) | (tex_hi.y != NO_TEXTURE ? 32u : 0u);
    uint bound = pending;
    vec4 t_base = vec4(1.0), t_mr = vec4(1.0), t_normal = vec4(0.0), t_emissive = vec4(1.0), t_spec = vec4(1.0), t_spec_color = vec4(1.0);
    while (pending != 0u) {
        int slot = findLSB(pending);
        pending &= pending - 1u;
        uint tex = slot == 0 ? tex_lo.x : slot == 1 ? tex_lo.y : slot == 2 ? tex_lo.z
            : slot == 3 ? tex_emissive : slot == 4 ? tex_hi.x : tex_hi.y;
        bool srgb = slot == 0 || slot == 3 || slot == 5;
        vec4 c = sample_texture_lod(tex, s.uv, srgb, lod_uv);
        if (slot == 0) t_base = c;
        if (slot == 1) t_mr = c;
        if (slot == 2) t_normal = c;
        if (slot == 3) t_emissive = c;
        if (slot == 4) t_spec = c;
        if (slot == 5) t_spec_color = c;
    }

    vec4 base = m.base_color;
    if ((bound & 1u) != 0u) base *= t_base;
    s.base_color = base.rgb;
    s.metallic = m.surface.x;
    s.roughness = m.surface.y;
    if ((bound & 2u) != 0u) {
        s.roughness *= t_mr.g;
        s.metallic *= t_mr.b;
    }
    if ((bound & 4u) != 0u) {
        vec4 t4 = w.x * a.tangent + w.y * b.tangent + w.z * c.tangent;
        vec3 t = normalize(t4.xyz - n * dot(n, t4.xyz));
        vec3 bt = cross(n, t) * (t4.w < 0.0 ? -1.0 : 1.0);
        vec3 tn = t_normal.xyz * 2.0 - 1.0;
        tn.xy *= m.surface.w;
        vec3 mapped = normalize(tn.x * t + tn.y * bt + tn.z * n);
        if (all(equal(mapped, mapped))) n = mapped; // keep the vertex normal if the map gives NaN
    }
    bool double_sided = (m.textures2.z & MATERIAL_DOUBLE_SIDED) != 0u;
    vec3 emission = m.emissive.rgb;
    if ((bound & 8u) != 0u) emission *= t_emissive.rgb;
    s.emission = (front || double_sided) ? emission : vec3(0.0);
    s.geometric_normal = front ? ng : -ng;
    if (dot(n, s.geometric_normal) < 0.0) n = -n;
    s.normal = n;
    float ior = m.surface.z;
    float f0 = (ior - 1.0) / (ior + 1.0);
    vec3 spec_color = m.specular.rgb;
    s.specular_factor = m.specular.w;
    if ((bound & 16u) != 0u) s.specular_factor *= t_spec.a;
    if ((bound & 32u) != 0u) spec_color *= t_spec_color.rgb;
    s.dielectric_f0 = min(vec3(f0 * f0) * spec_color, vec3(1.0));
    return s;
}

// Ray origin pushed off the surface along the geometric normal, robust at any scale
// (Wächter & Binder, Ray Tracing Gems ch. 6).
vec3 offset_ray(vec3 p, vec3 n) {
    const float origin = 1.0 / 32.0, float_scale = 1.0 / 65536.0, int_scale = 256.0;
    ivec3 of_i = ivec3(int_scale * n);
    vec3 p_i = vec3(
        intBitsToFloat(floatBitsToInt(p.x) + ((p.x < 0.0) ? -of_i.x : of_i.x)),
        intBitsToFloat(floatBitsToInt(p.y) + ((p.y < 0.0) ? -of_i.y : of_i.y)),
        intBitsToFloat(floatBitsToInt(p.z) + ((p.z < 0.0) ? -of_i.z : of_i.z)));
    return vec3(
        abs(p.x) < origin ? p.x + float_scale * n.x : p_i.x,
        abs(p.y) < origin ? p.y + float_scale * n.y : p_i.y,
        abs(p.z) < origin ? p.z + float_scale * n.z : p_i.z);
}

#endif
