// BVH2 traversal over texel buffers (5–6× faster than std430 reads on lavapipe). Node = 4 RGBA32F
// texels holding both children's boxes; triangles = 3 texels in leaf order (see fovea_scene::bvh).
// Needs `bvh_nodes` and `bvh_triangles` (samplerBuffer) declared by the includer.
#ifndef FOVEA_BVH_GLSL
#define FOVEA_BVH_GLSL

const int BVH_STACK_SIZE = 64; // the upload refuses deeper trees

// The traversal stack lives in shared memory, one slice per invocation: lavapipe lowers a
// dynamically indexed private array into chains of selects, which made traversal ~20× slower.
// Every kernel that traces uses 64 invocations per workgroup (WORKGROUP_2D² = WORKGROUP_1D).
shared uint bvh_stack[64 * BVH_STACK_SIZE];

struct Hit {
    float t;
    float u;            // barycentric weight of v1
    float v;            // barycentric weight of v2
    uint triangle;      // original triangle index
};

// Watertight ray/triangle test (Woop, Benthin, Wald 2013), two-sided; same algorithm as
// fovea_scene::intersect::intersect_triangle so the CPU reference agrees.
struct RayShear {
    ivec3 k;            // kx, ky, kz axis permutation
    vec3 s;             // Sx, Sy, Sz
};

RayShear ray_shear(vec3 dir) {
    vec3 a = abs(dir);
    int kz = (a.x > a.y) ? ((a.x > a.z) ? 0 : 2) : ((a.y > a.z) ? 1 : 2);
    int kx = (kz + 1) % 3;
    int ky = (kx + 1) % 3;
    if (dir[kz] < 0.0) { int tmp = kx; kx = ky; ky = tmp; }
    RayShear r;
    r.k = ivec3(kx, ky, kz);
    r.s = vec3(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
    return r;
}

// Returns true and (t, u, v) when the ray hits inside (tmin, tmax).
bool intersect_triangle(vec3 org, RayShear sh, vec3 v0, vec3 v1, vec3 v2, float tmin, float tmax, out vec3 tuv) {
    vec3 A = v0 - org, B = v1 - org, C = v2 - org;
    float Ax = A[sh.k.x] - sh.s.x * A[sh.k.z], Ay = A[sh.k.y] - sh.s.y * A[sh.k.z];
    float Bx = B[sh.k.x] - sh.s.x * B[sh.k.z], By = B[sh.k.y] - sh.s.y * B[sh.k.z];
    float Cx = C[sh.k.x] - sh.s.x * C[sh.k.z], Cy = C[sh.k.y] - sh.s.y * C[sh.k.z];
    float U = Cx * By - Cy * Bx;
    float V = Ax * Cy - Ay * Cx;
    float W = Bx * Ay - By * Ax;
    if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
    float det = U + V + W;
    if (det == 0.0) return false;
    float T = sh.s.z * (U * A[sh.k.z] + V * B[sh.k.z] + W * C[sh.k.z]);
    float inv = 1.0 / det;
    float t = T * inv;
    if (!(t > tmin && t < tmax)) return false;
    tuv = vec3(t, V * inv, W * inv);
    return true;
}

// Slab test of one box; returns the entry distance or +inf when missed.
float box_entry(vec3 bmin, vec3 bmax, vec3 org_over_dir, vec3 inv_dir, float tmin, float tmax) {
    if (bmin.x > bmax.x) return 1e30; // an empty child (inverted box): the slab test would accept it
    vec3 t0 = bmin * inv_dir - org_over_dir;
    vec3 t1 = bmax * inv_dir - org_over_dir;
    vec3 lo = min(t0, t1), hi = max(t0, t1);
    float enter = max(max(lo.x, lo.y), max(lo.z, tmin));
    float leave = min(min(hi.x, hi.y), min(hi.z, tmax));
    return enter <= leave ? enter : 1e30;
}

// Tests the triangles of one leaf, shrinking hit.t; true when any was hit.
bool intersect_leaf(vec3 org, RayShear sh, uint first, uint count, float tmin, bool any_hit, inout Hit hit) {
    bool found = false;
    for (uint i = first; i < first + count; ++i) {
        int tb = int(i) * 3;
        vec4 t0 = texelFetch(bvh_triangles, tb + 0);
        vec4 t1 = texelFetch(bvh_triangles, tb + 1);
        vec4 t2 = texelFetch(bvh_triangles, tb + 2);
        vec3 tuv;
        if (intersect_triangle(org, sh, t0.xyz, t1.xyz, t2.xyz, tmin, hit.t, tuv)) {
            hit.t = tuv.x;
            hit.u = tuv.y;
            hit.v = tuv.z;
            hit.triangle = floatBitsToUint(t0.w);
            found = true;
            if (any_hit) return true;
        }
    }
    return found;
}

// Closest hit (any_hit = false) or first hit found (shadow rays, any_hit = true).
bool bvh_trace(vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, out Hit hit) {
    hit.t = tmax;
    hit.triangle = 0xffffffffu;
    hit.u = 0.0;
    hit.v = 0.0;
    RayShear sh = ray_shear(dir);
    // Avoid inf*0 = NaN in the slab test for axis-parallel rays.
    vec3 safe = mix(dir, vec3(1e-20), lessThan(abs(dir), vec3(1e-20)));
    vec3 inv_dir = 1.0 / safe;
    vec3 ood = org * inv_dir;
    uint stack_base = gl_LocalInvocationIndex * uint(BVH_STACK_SIZE);
    int sp = 0;
    uint node = 0u;
    while (true) {
        int base = int(node) * 4;
        vec4 n0 = texelFetch(bvh_nodes, base + 0);
        vec4 n1 = texelFetch(bvh_nodes, base + 1);
        vec4 n2 = texelFetch(bvh_nodes, base + 2);
        vec4 n3 = texelFetch(bvh_nodes, base + 3);
        uint child0 = floatBitsToUint(n0.w), child1 = floatBitsToUint(n1.w);
        uint count0 = floatBitsToUint(n2.w), count1 = floatBitsToUint(n3.w);
        float e0 = box_entry(n0.xyz, n1.xyz, ood, inv_dir, tmin, hit.t);
        float e1 = box_entry(n2.xyz, n3.xyz, ood, inv_dir, tmin, hit.t);
        bool hit0 = e0 < 1e30, hit1 = e1 < 1e30;
        if (hit0 && count0 != 0u) {
            if (intersect_leaf(org, sh, child0, count0, tmin, any_hit, hit) && any_hit) return true;
            hit0 = false;
        }
        if (hit1 && count1 != 0u) {
            if (intersect_leaf(org, sh, child1, count1, tmin, any_hit, hit) && any_hit) return true;
            hit1 = false;
        }
        if (hit0 && hit1) {
            bool left_first = e0 <= e1;
            if (sp < BVH_STACK_SIZE) bvh_stack[stack_base + uint(sp++)] = left_first ? child1 : child0;
            node = left_first ? child0 : child1;
        } else if (hit0) {
            node = child0;
        } else if (hit1) {
            node = child1;
        } else {
            if (sp == 0) break;
            node = bvh_stack[stack_base + uint(--sp)];
        }
    }
    return hit.triangle != 0xffffffffu;
}

#endif
