// The glTF metallic-roughness BRDF with KHR_materials_specular/_ior: a Lambertian base mixed with
// a GGX lobe by the (specular-factor-scaled) Fresnel term, and a metal GGX lobe. Sampling picks a
// lobe by an estimate of its weight and returns the one-sample-MIS weight over both lobes.
// specular_factor = 0 and metallic = 0 give exactly base_color / π.
#ifndef FOVEA_BRDF_GLSL
#define FOVEA_BRDF_GLSL

const float PI = 3.14159265358979;
// Below this roughness the GGX lobe is treated as a perfect mirror (a delta distribution).
const float MIRROR_ROUGHNESS = 0.02;

vec3 fresnel_schlick(vec3 f0, float cos_theta) {
    float m = clamp(1.0 - cos_theta, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (1.0 - f0) * (m2 * m2 * m);
}

float max3(vec3 v) { return max(v.x, max(v.y, v.z)); }

// Orthonormal basis around n (Duff et al. 2017).
mat3 basis(vec3 n) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    vec3 t = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    vec3 bt = vec3(b, s + n.y * n.y * a, -n.y);
    return mat3(t, bt, n);
}

float ggx_d(float n_h, float alpha) {
    float a2 = alpha * alpha;
    float d = n_h * n_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

float smith_g1(float n_x, float alpha) {
    float a2 = alpha * alpha;
    return 2.0 * n_x / (n_x + sqrt(a2 + (1.0 - a2) * n_x * n_x));
}

// Height-correlated Smith G2 divided by 4·n·l·n·v (the "visibility" term).
float smith_visibility(float n_l, float n_v, float alpha) {
    float a2 = alpha * alpha;
    float gv = n_l * sqrt(n_v * n_v * (1.0 - a2) + a2);
    float gl = n_v * sqrt(n_l * n_l * (1.0 - a2) + a2);
    return 0.5 / max(gv + gl, 1e-12);
}

// Visible-normal sampling of GGX (Heitz 2018) in the local frame (z = normal).
vec3 sample_ggx_vndf(vec3 v_local, float alpha, vec2 u) {
    vec3 vh = normalize(vec3(alpha * v_local.x, alpha * v_local.y, v_local.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(1.0 - p1 * p1) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(0.0, nh.z)));
}

// pdf of a reflected direction under VNDF sampling: G1(v) D(h) / (4 n·v).
float ggx_vndf_pdf(float n_v, float n_h, float alpha) {
    return smith_g1(n_v, alpha) * ggx_d(n_h, alpha) / (4.0 * max(n_v, 1e-8));
}

bool is_mirror(Surface s) { return s.roughness < MIRROR_ROUGHNESS; }

// Probability of sampling the specular lobe.
float specular_probability(Surface s, float n_v) {
    float dielectric = s.specular_factor * max3(fresnel_schlick(s.dielectric_f0, n_v));
    return clamp(mix(dielectric, 1.0, s.metallic), 0.0, 1.0);
}

// f(v, l)·cos for the non-delta part of the BRDF (the mirror lobe is skipped when delta).
vec3 brdf_eval_cos(Surface s, vec3 v, vec3 l) {
    float n_l = dot(s.normal, l);
    float n_v = dot(s.normal, v);
    if (n_l <= 0.0 || n_v <= 0.0 || dot(s.geometric_normal, l) <= 0.0) return vec3(0.0);
    vec3 h = normalize(v + l);
    float v_h = max(dot(v, h), 0.0);
    vec3 fd = s.specular_factor * fresnel_schlick(s.dielectric_f0, v_h);
    vec3 diffuse = (1.0 - s.metallic) * (1.0 - fd) * s.base_color / PI;
    if (is_mirror(s)) return diffuse * n_l;
    float alpha = max(s.roughness * s.roughness, 1e-4);
    float spec = ggx_d(max(dot(s.normal, h), 0.0), alpha) * smith_visibility(n_l, n_v, alpha);
    vec3 f = mix(fd, fresnel_schlick(s.base_color, v_h), s.metallic);
    return (diffuse + f * spec) * n_l;
}

// Combined pdf of the non-delta lobes for direction l.
float brdf_pdf(Surface s, vec3 v, vec3 l) {
    float n_l = dot(s.normal, l);
    float n_v = dot(s.normal, v);
    if (n_l <= 0.0 || n_v <= 0.0) return 0.0;
    float ps = specular_probability(s, n_v);
    float pdf = (1.0 - ps) * n_l / PI;
    if (!is_mirror(s)) {
        float alpha = max(s.roughness * s.roughness, 1e-4);
        pdf += ps * ggx_vndf_pdf(n_v, max(dot(s.normal, normalize(v + l)), 0.0), alpha);
    }
    return pdf;
}

// Samples a direction; returns false when the path ends. `weight` = f·cos / pdf; `delta` marks
// a mirror reflection (next-event estimation could not have found that light; `pdf` is then
// 1e30, "infinite"), otherwise `pdf` is the sampled direction's solid-angle density.
bool brdf_sample(Surface s, vec3 v, vec3 u, out vec3 l, out vec3 weight, out bool delta, out float pdf) {
    delta = false;
    weight = vec3(0.0);
    pdf = 1e30;
    float n_v = dot(s.normal, v);
    if (n_v <= 0.0) return false;
    float ps = specular_probability(s, n_v);
    mat3 frame = basis(s.normal);
    if (u.z < ps) {
        if (is_mirror(s)) {
            l = reflect(-v, s.normal);
            if (dot(s.geometric_normal, l) <= 0.0) return false;
            vec3 fd = s.specular_factor * fresnel_schlick(s.dielectric_f0, n_v);
            vec3 f = mix(fd, fresnel_schlick(s.base_color, n_v), s.metallic);
            weight = f / ps;
            delta = true;
            pdf = 1e30;
            return true;
        }
        float alpha = max(s.roughness * s.roughness, 1e-4);
        vec3 h = frame * sample_ggx_vndf(transpose(frame) * v, alpha, u.xy);
        l = reflect(-v, h);
    } else {
        float r = sqrt(u.x), phi = 2.0 * PI * u.y;
        l = frame * vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
    }
    pdf = brdf_pdf(s, v, l);
    if (pdf <= 0.0) return false;
    weight = brdf_eval_cos(s, v, l) / pdf;
    return any(greaterThan(weight, vec3(0.0)));
}

// Path regularisation (Kaplanyan & Dachsbacher 2013, in the practical form of Cycles' "filter
// glossy"): a vertex reached through bounces whose smallest density was `min_pdf` gets a GGX
// alpha of at least ½·sqrt(1 − k·min_pdf) while k·min_pdf < 1. After a diffuse bounce (pdf ≤ 1/π)
// a near-specular lobe is widened, so sunlight that only next-event estimation can find through it
// (diffuse → glossy → sun: caustic fireflies) spreads over many samples instead of a few; a
// sharp earlier bounce (high pdf) leaves mirror-in-mirror reflections as they are. k = 0: unbiased.
void regularise(inout Surface s, float min_pdf, float k) {
    float b = k * min_pdf;
    if (k <= 0.0 || b >= 1.0) return;
    s.roughness = max(s.roughness, sqrt(0.5 * sqrt(1.0 - b)));
}

#endif
