// SVGF (Schied et al. 2017) helpers shared by its kernels: luminance, the per-sample surface the
// edge-stopping functions and the reprojection test compare, and the edge-stopping weight.
#ifndef FOVEA_DENOISE_SVGF_GLSL
#define FOVEA_DENOISE_SVGF_GLSL

// Reprojection accepts a previous sample of the same mesh whose depth differs by less than this
// many depth-gradients (one texel of the surface's own slope; covers jitter and the bilinear
// footprint) plus a relative slack, and whose normal is within ~25°.
const float SVGF_REPROJECT_GRADIENTS = 3.0;
const float SVGF_REPROJECT_DEPTH_SLACK = 0.005;
const float SVGF_REPROJECT_NORMAL_COS = 0.9;
// Floor of the depth gradient per texel, relative to depth: a face-on plane has an analytic
// gradient of 0, and round-off alone must not stop the filter there.
const float SVGF_MIN_GRADIENT = 1e-3;

float svgf_luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

// Non-negative and finite, with the luminance capped (fireflies may not overflow the moments).
vec3 svgf_sanitize(vec3 c) {
    if (any(isnan(c)) || any(isinf(c))) return vec3(0.0);
    c = max(c, vec3(0.0));
    float l = svgf_luminance(c);
    return l > SVGF_MAX_LUMINANCE ? c * (SVGF_MAX_LUMINANCE / l) : c;
}

struct SvgfSurface {
    vec3 normal;     // zero where nothing was hit
    float depth;     // linear view depth, 0: miss
    float gradient;  // depth change per grid texel
    uint key;        // mesh + 1, 0: miss (or no sample)
};

SvgfSurface svgf_surface(vec4 normal_depth, float gradient, uvec2 ids) {
    SvgfSurface s;
    s.normal = normal_depth.xyz;
    s.depth = normal_depth.w;
    s.gradient = max(gradient, SVGF_MIN_GRADIENT * normal_depth.w);
    s.key = ids.x == 0u ? 0u : (ids.y >> 16u) + 1u;
    return s;
}

// Octahedral normal in two snorm16, depth and gradient as float bits, mesh key.
uvec4 svgf_pack_surface(SvgfSurface s) {
    vec3 n = s.normal / max(abs(s.normal.x) + abs(s.normal.y) + abs(s.normal.z), 1e-20);
    vec2 o = n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return uvec4(packSnorm2x16(o), floatBitsToUint(s.depth), floatBitsToUint(s.gradient), s.key);
}

SvgfSurface svgf_unpack_surface(uvec4 u) {
    SvgfSurface s;
    vec2 o = unpackSnorm2x16(u.x);
    vec3 n = vec3(o, 1.0 - abs(o.x) - abs(o.y));
    float t = max(-n.z, 0.0);
    n.xy += vec2(n.x >= 0.0 ? -t : t, n.y >= 0.0 ? -t : t);
    s.depth = uintBitsToFloat(u.y);
    s.gradient = uintBitsToFloat(u.z);
    s.key = u.w;
    s.normal = s.key == 0u ? vec3(0.0) : normalize(n);
    return s;
}

// May the history of `prev` continue at `cur`? Same mesh, close depth, similar normal.
bool svgf_same_surface(SvgfSurface cur, SvgfSurface prev) {
    if (cur.key != prev.key) return false;
    if (cur.key == 0u) return true;
    float tolerance = SVGF_REPROJECT_GRADIENTS * max(cur.gradient, prev.gradient) + SVGF_REPROJECT_DEPTH_SLACK * cur.depth;
    return abs(cur.depth - prev.depth) <= tolerance && dot(cur.normal, prev.normal) >= SVGF_REPROJECT_NORMAL_COS;
}

// SVGF's edge-stopping weight between a centre and a tap `distance` texels away: depth relative to
// the centre's gradient, normal power σ_n, luminance relative to `phi_l` (σ_l·√variance).
float svgf_edge_weight(SvgfSurface c, SvgfSurface q, float distance, float sigma_z, float sigma_n, float dl, float phi_l) {
    float cos_n = dot(c.normal, q.normal);
    float w_n = cos_n > 0.0 ? pow(cos_n, sigma_n) : 0.0;
    float phi_z = sigma_z * c.gradient * distance + 1e-6;
    return exp(-abs(c.depth - q.depth) / phi_z - abs(dl) / phi_l) * w_n;
}

#endif
