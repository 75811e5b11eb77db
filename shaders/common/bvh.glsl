// BVH traversal, one of two per device class (fovea_renderer::traversal, `--traversal`):
// - the CPU-driver traversal (default): 4-wide nodes over texel buffers (5–6× faster than std430
//   reads on lavapipe), node = 8 RGBA32F texels, one component per child (fovea_scene::bvh::wide),
//   triangles = 3 texels in leaf order, a stack in registers spilling to shared memory;
// - the GPU traversal (BVH_TRAVERSAL_GPU, the `+gpu` variant of every kernel that traces):
//   compressed 8-wide nodes of 80 bytes read as uvec4 from a storage buffer
//   (fovea_scene::bvh::compressed), children visited in order of entry distance, a stack of
//   (entry, distance) pairs in private memory, farther entries skipped once a closer hit is known.
// Needs the scene's BVH buffers (scene.glsl), `instances` and `frame` declared by the includer. The
// world tree's root is node 0; with instances (fovea_scene::bvh::instanced) a top level over them
// follows, leading to each instanced mesh's object-space tree (all in the same buffers).
// BVH_COUNTERS (the `counters` variant of passes/raycast): each walk adds what it read to
// bvh_counts; without it the counting compiles to nothing.
#ifndef FOVEA_BVH_GLSL
#define FOVEA_BVH_GLSL

#if defined(BVH_COUNTERS)
// Nodes opened, leaf triangles tested, alpha tests, bytes of node + triangle (+ instance) data read.
uvec4 bvh_counts = uvec4(0u);
#define BVH_COUNT(nodes, triangles, alpha, bytes) bvh_counts += uvec4(nodes, triangles, alpha, bytes)
#else
#define BVH_COUNT(nodes, triangles, alpha, bytes)
#endif

// A leaf triangle's flag word (second texel's w): its material is alpha-masked or blended
// (fovea_scene::bvh::compressed::TRIANGLE_ALPHA_TESTED), so opaque triangles never reach the test.
const uint TRIANGLE_ALPHA_TESTED = 1u;
// Bytes read per 4-wide node, per 8-wide node, per leaf triangle and per instance entered (its
// leaf entry and its InstanceGpu), as fovea_scene's CPU twins count them.
const uint BVH4_NODE_BYTES = 128u;
const uint BVH8_NODE_BYTES = 80u;
const uint BVH_TRIANGLE_BYTES = 48u;
const uint BVH_INSTANCE_BYTES = 128u;

struct Hit {
    float t;
    float u;            // barycentric weight of v1
    float v;            // barycentric weight of v2
    uint triangle;      // original triangle index
};

// Watertight ray/triangle test (Woop, Benthin, Wald 2013), two-sided; same algorithm as
// fovea_scene::intersect::intersect_triangle so the CPU reference agrees.
//
// lavapipe runs 8 lanes in SIMD and executes both sides of every `if` under a mask, so cost is the
// static instruction count of the loop bodies. The per-lane axis permutation is therefore resolved
// once per ray into select masks (a dynamic vector index costs a compare+select chain each time).
struct RayShear {
    bvec2 kx, ky, kz;   // (k == 0, k == 1) for each of kx, ky, kz
    vec3 org;           // origin permuted to (kx, ky, kz)
    vec3 s;             // Sx, Sy, Sz
};

float pick(vec3 v, bvec2 k) { return k.x ? v.x : (k.y ? v.y : v.z); }

RayShear ray_shear(vec3 org, vec3 dir) {
    vec3 a = abs(dir);
    int kz = (a.x > a.y) ? ((a.x > a.z) ? 0 : 2) : ((a.y > a.z) ? 1 : 2);
    int kx = (kz + 1) % 3;
    int ky = (kx + 1) % 3;
    if (dir[kz] < 0.0) { int tmp = kx; kx = ky; ky = tmp; }
    RayShear r;
    r.kx = bvec2(kx == 0, kx == 1);
    r.ky = bvec2(ky == 0, ky == 1);
    r.kz = bvec2(kz == 0, kz == 1);
    r.org = vec3(pick(org, r.kx), pick(org, r.ky), pick(org, r.kz));
    vec3 d = vec3(pick(dir, r.kx), pick(dir, r.ky), pick(dir, r.kz));
    r.s = vec3(d.x / d.z, d.y / d.z, 1.0 / d.z);
    return r;
}

// A vertex moved to ray space before the shear: (v[kx], v[ky], v[kz]) − permuted origin. Exactly
// (v − org)[k] of the textbook form, so results are bit-identical to the CPU reference.
vec3 to_ray(RayShear sh, vec3 v) {
    return vec3(pick(v, sh.kx), pick(v, sh.ky), pick(v, sh.kz)) - sh.org;
}

// Returns true and (t, u, v) when the ray hits inside (tmin, tmax).
bool intersect_triangle(RayShear sh, vec3 v0, vec3 v1, vec3 v2, float tmin, float tmax, out vec3 tuv) {
    vec3 A = to_ray(sh, v0), B = to_ray(sh, v1), C = to_ray(sh, v2);
    float Ax = A.x - sh.s.x * A.z, Ay = A.y - sh.s.y * A.z;
    float Bx = B.x - sh.s.x * B.z, By = B.y - sh.s.y * B.z;
    float Cx = C.x - sh.s.x * C.z, Cy = C.y - sh.s.y * C.z;
    float U = Cx * By - Cy * Bx;
    float V = Ax * Cy - Ay * Cx;
    float W = Bx * Ay - By * Ax;
    float det = U + V + W;
    float T = sh.s.z * (U * A.z + V * B.z + W * C.z);
    float inv = 1.0 / det;
    float t = T * inv;
    tuv = vec3(t, V * inv, W * inv);
    bool outside = (U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0);
    return !outside && det != 0.0 && t > tmin && t < tmax;
}

// Box tests over-estimate the exit distance by 2γ₃ (Ize 2013) so rounding never culls a box that
// holds a hit; identical to fovea_scene::bvh::slab_test.
const float SLAB_SLACK = 1.0 + 2.0 * (3.0 * 5.9604645e-8) / (1.0 - 3.0 * 5.9604645e-8);

// Sorts (key, ref) pairs a and b so that a has the smaller key (a compare-exchange).
void cswap(inout float ka, inout uint ra, inout float kb, inout uint rb) {
    bool sw = kb < ka;
    float k = ka; uint r = ra;
    ka = sw ? kb : ka; ra = sw ? rb : ra;
    kb = sw ? k : kb; rb = sw ? r : rb;
}

// Like fovea_scene::bvh::safe_inverse_dir: a zero component becomes ±1e-30 (no 0·inf = NaN).
vec3 safe_inverse_dir(vec3 dir) {
    bvec3 zero = equal(dir, vec3(0.0));
    vec3 signed_tiny = uintBitsToFloat((floatBitsToUint(dir) & 0x80000000u) | floatBitsToUint(1e-30));
    return 1.0 / mix(dir, signed_tiny, zero);
}

// Whether a candidate hit on a leaf triangle is cut away by its material's alpha (alpha-masked
// scenes only, a frame flag, and only triangles flagged in their leaf data).
bool alpha_cuts(uint flags, uint triangle, uint id, float u, float v) {
    if ((frame.data.frame.w & FRAME_FLAG_ALPHA_MASK) == 0u || (flags & TRIANGLE_ALPHA_TESTED) == 0u) return false;
    BVH_COUNT(0u, 0u, 1u, 0u);
    return alpha_rejects(triangle, id, u, v);
}

#if !defined(BVH_TRAVERSAL_GPU)
const int BVH_STACK_SIZE = 64; // the upload refuses trees whose traversal could push more (Bvh4::max_stack)

// Overflow of the traversal stack (below its 8 register entries) lives in shared memory, one slice
// per invocation: lavapipe turns a dynamically indexed array (private or shared) into per-lane
// scalar loops, so the hot top of the stack is kept in registers instead.
// Every kernel that traces uses 64 invocations per workgroup (WORKGROUP_2D² = WORKGROUP_1D).
shared uint bvh_stack[64 * BVH_STACK_SIZE];
// The top level's stack (it calls the tree walk, which uses bvh_stack, at its leaves); the upload
// refuses top levels that could push more.
const int TOP_STACK_SIZE = 16;
shared uint top_stack[64 * TOP_STACK_SIZE];

// Reads 4-wide node `node` (8 texels, one component per child: fovea_scene::bvh::wide) and
// slab-tests its four children at once, each as fovea_scene::bvh::slab_test with tmin for 0:
// which children the ray enters before `limit`, their entry distances, references and counts.
bvec4 node_children_hit(uint node, vec3 org, vec3 inv_dir, float tmin, float limit, out uvec4 refs, out uvec4 counts, out vec4 enter) {
    int base = int(node) * 8;
    vec4 lox = texelFetch(bvh_nodes, base + 0), loy = texelFetch(bvh_nodes, base + 1), loz = texelFetch(bvh_nodes, base + 2);
    vec4 hix = texelFetch(bvh_nodes, base + 3), hiy = texelFetch(bvh_nodes, base + 4), hiz = texelFetch(bvh_nodes, base + 5);
    refs = floatBitsToUint(texelFetch(bvh_nodes, base + 6));
    counts = floatBitsToUint(texelFetch(bvh_nodes, base + 7));
    vec4 ax = (lox - org.x) * inv_dir.x, bx = (hix - org.x) * inv_dir.x;
    vec4 ay = (loy - org.y) * inv_dir.y, by = (hiy - org.y) * inv_dir.y;
    vec4 az = (loz - org.z) * inv_dir.z, bz = (hiz - org.z) * inv_dir.z;
    enter = max(max(min(ax, bx), min(ay, by)), max(min(az, bz), vec4(tmin)));
    vec4 leave = min(min(max(ax, bx), max(ay, by)), max(az, bz)) * SLAB_SLACK;
    // An empty child is an inverted box: the slab test alone would accept it.
    return bvec4(uvec4(lessThanEqual(enter, leave)) & uvec4(lessThanEqual(enter, vec4(limit))) & uvec4(lessThanEqual(lox, hix)));
}

// Walks one tree from `root`, continuing `hit` (closest: smallest (t, placed id), the CPU
// reference's tie rule; any_hit: stops at the first hit and returns true). A leaf entry's
// texel w = k is placed id id_base + k and TriangleGpu tri_base + k (the world tree: 0, 0).
// Same algorithm as fovea_scene::bvh::wide::Bvh4::intersect_into: 4-wide nodes (8 texels, one
// component per child), the hit leaves' triangles tested on the spot in one loop, interior
// children visited nearest first.
bool bvh_walk(uint root, vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, uint tri_base, uint id_base, inout Hit hit) {
    RayShear sh = ray_shear(org, dir);
    vec3 inv_dir = safe_inverse_dir(dir);
    float limit = hit.t * SLAB_SLACK;
    // Traversal stack: the top 8 entries in registers (s0 = top), shifted on push/pop; deeper
    // entries in this invocation's slice of shared memory.
    uint s0 = 0u, s1 = 0u, s2 = 0u, s3 = 0u, s4 = 0u, s5 = 0u, s6 = 0u, s7 = 0u;
    uint stack_base = gl_LocalInvocationIndex * uint(BVH_STACK_SIZE);
    int sp = 0;
    uint node = root;
    bool done = false, found = false;
    while (!done) {
        uvec4 refs, counts;
        vec4 enter;
        BVH_COUNT(1u, 0u, 0u, BVH4_NODE_BYTES);
        bvec4 hit4 = node_children_hit(node, org, inv_dir, tmin, limit, refs, counts, enter);
        uvec4 leaf = uvec4(hit4) * counts;
        // Leaves: all hit leaves' triangles in one loop, in slot order.
        uint c01 = leaf.x + leaf.y, c012 = c01 + leaf.z, n_leaf = c012 + leaf.w;
        for (uint i = 0u; i < n_leaf; ++i) {
            uint tri = i < leaf.x ? refs.x + i
                     : i < c01 ? refs.y + (i - leaf.x)
                     : i < c012 ? refs.z + (i - c01)
                     : refs.w + (i - c012);
            int tb = int(tri) * 3;
            BVH_COUNT(0u, 1u, 0u, BVH_TRIANGLE_BYTES);
            vec4 t0 = texelFetch(bvh_triangles, tb + 0);
            vec4 t1 = texelFetch(bvh_triangles, tb + 1);
            vec4 t2 = texelFetch(bvh_triangles, tb + 2);
            uint k = floatBitsToUint(t0.w);
            uint id = id_base + k;
            vec3 tuv;
            // A cut-out is no hit.
            if (intersect_triangle(sh, t0.xyz, t1.xyz, t2.xyz, tmin, tmax, tuv)
                && (tuv.x < hit.t || (tuv.x == hit.t && id < hit.triangle))
                && !alpha_cuts(floatBitsToUint(t1.w), tri_base + k, id, tuv.y, tuv.z)) {
                hit.t = tuv.x;
                hit.u = tuv.y;
                hit.v = tuv.z;
                hit.triangle = id;
                limit = hit.t * SLAB_SLACK;
                if (any_hit) { done = true; found = true; break; }
            }
        }
        if (done) break;
        // Interior children: sort by entry distance (misses and leaves get 1e30), visit the
        // nearest, push the others farthest first.
        bvec4 inner = bvec4(uvec4(hit4) & uvec4(equal(counts, uvec4(0u))));
        vec4 key = mix(vec4(1e30), enter, inner);
        float k0 = key.x, k1 = key.y, k2 = key.z, k3 = key.w;
        uint r0 = refs.x, r1 = refs.y, r2 = refs.z, r3 = refs.w;
        cswap(k0, r0, k1, r1); cswap(k2, r2, k3, r3); cswap(k0, r0, k2, r2); cswap(k1, r1, k3, r3); cswap(k1, r1, k2, r2);
        int n_inner = int(inner.x) + int(inner.y) + int(inner.z) + int(inner.w);
        if (n_inner == 0) {
            if (sp == 0) {
                done = true;
            } else {
                node = s0; s0 = s1; s1 = s2; s2 = s3; s3 = s4; s4 = s5; s5 = s6; s6 = s7;
                if (--sp >= 8) s7 = bvh_stack[stack_base + uint(sp - 8)];
            }
        } else {
            node = r0;
            // Push r3, r2, r1 as present (r1 ends on top: the second nearest is popped first).
            for (int k = n_inner - 1; k >= 1; --k) {
                uint r = k == 3 ? r3 : (k == 2 ? r2 : r1);
                // The deepest register entry spills to shared memory when all 8 are in use.
                if (sp >= 8 && sp < BVH_STACK_SIZE) bvh_stack[stack_base + uint(sp - 8)] = s7;
                s7 = s6; s6 = s5; s5 = s4; s4 = s3; s3 = s2; s2 = s1; s1 = s0; s0 = r;
                sp = min(sp + 1, BVH_STACK_SIZE + 8);
            }
        }
    }
    return found;
}

#endif // !BVH_TRAVERSAL_GPU

// The ray in an instance's object space (rows of its inverse), with fovea_scene's arithmetic
// (InstanceRay::to_object). The direction stays unnormalised, so t is the same parameter.
void to_object(InstanceGpu inst, vec3 org, vec3 dir, out vec3 o, out vec3 d) {
    vec4 r0 = inst.object_from_world0, r1 = inst.object_from_world1, r2 = inst.object_from_world2;
    o = vec3(r0.x * org.x + r0.y * org.y + r0.z * org.z + r0.w,
             r1.x * org.x + r1.y * org.y + r1.z * org.z + r1.w,
             r2.x * org.x + r2.y * org.y + r2.z * org.z + r2.w);
    d = vec3(r0.x * dir.x + r0.y * dir.y + r0.z * dir.z,
             r1.x * dir.x + r1.y * dir.y + r1.z * dir.z,
             r2.x * dir.x + r2.y * dir.y + r2.z * dir.z);
}

#if !defined(BVH_TRAVERSAL_GPU)
// The top level (frame.data.instancing): its leaves hold instance indices (one texel each from
// texel instancing.w); each instance hit walks its mesh's tree with the ray in object space. As
// fovea_scene::bvh::instanced::SceneBvh::intersect (the closest hit does not depend on the order).
bool instances_walk(vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, inout Hit hit) {
    vec3 inv_dir = safe_inverse_dir(dir);
    uint stack_base = gl_LocalInvocationIndex * uint(TOP_STACK_SIZE);
    int sp = 0;
    uint node = frame.data.instancing.z;
    while (true) {
        uvec4 refs, counts;
        vec4 enter;
        BVH_COUNT(1u, 0u, 0u, BVH4_NODE_BYTES);
        bvec4 hit4 = node_children_hit(node, org, inv_dir, tmin, hit.t * SLAB_SLACK, refs, counts, enter);
        bool have_next = false;
        uint next = 0u;
        for (int c = 0; c < 4; ++c) {
            if (!hit4[c]) continue;
            if (counts[c] == 0u) {
                // The first interior child is visited next, the others wait on the stack.
                if (have_next && sp < TOP_STACK_SIZE) top_stack[stack_base + uint(sp++)] = refs[c];
                if (!have_next) { next = refs[c]; have_next = true; }
                continue;
            }
            for (uint i = 0u; i < counts[c]; ++i) {
                BVH_COUNT(0u, 0u, 0u, BVH_INSTANCE_BYTES);
                uint k = floatBitsToUint(texelFetch(bvh_triangles, int(frame.data.instancing.w + refs[c] + i)).x);
                InstanceGpu inst = instances.data[k];
                vec3 o, d;
                to_object(inst, org, dir, o, d);
                if (bvh_walk(inst.mesh.y, o, d, tmin, tmax, any_hit, inst.mesh.z, inst.mesh.x, hit)) return true;
            }
        }
        if (have_next) {
            node = next;
        } else if (sp > 0) {
            node = top_stack[stack_base + uint(--sp)];
        } else {
            return false;
        }
    }
}

#endif // !BVH_TRAVERSAL_GPU

#if defined(BVH_TRAVERSAL_GPU)
// The stacks' sizes (fovea_scene::bvh::compressed::STACK_SIZE, gpu_scene::MAX_TOP_STACK_GPU): the
// upload refuses trees whose traversal could push more (Bvh8::max_stack).
const int BVH8_STACK_SIZE = 128;
const int BVH8_TOP_STACK_SIZE = 32;
// A child or stack entry: a node index, or a leaf slot (bit 31) as first triangle entry << 2 | count.
const uint BVH8_LEAF = 0x80000000u;

// One half (four slots) of a compressed node: entry distance per slot (+inf where the ray does not
// reach it before `limit`, or the slot is empty) and the slot's entry. Box planes decode exactly
// (origin + q·2^e, see fovea_scene::bvh::compressed), then the slab test of node_children_hit.
void bvh8_half(uvec4 slots, uvec4 planes_xy, uvec4 planes_z, uint meta4, vec3 origin, vec3 scale, uint imask,
               uvec2 bases, vec3 org, vec3 inv_dir, float tmin, float limit, out vec4 key, out uvec4 entry) {
    const uvec4 shift = uvec4(0u, 8u, 16u, 24u);
    // planes_xy: lo.x, hi.x, lo.y, hi.y bytes of the four slots; planes_z: lo.z, hi.z.
    vec4 lx = origin.x + vec4((uvec4(planes_xy.x) >> shift) & 0xffu) * scale.x;
    vec4 hx = origin.x + vec4((uvec4(planes_xy.y) >> shift) & 0xffu) * scale.x;
    vec4 ly = origin.y + vec4((uvec4(planes_xy.z) >> shift) & 0xffu) * scale.y;
    vec4 hy = origin.y + vec4((uvec4(planes_xy.w) >> shift) & 0xffu) * scale.y;
    vec4 lz = origin.z + vec4((uvec4(planes_z.x) >> shift) & 0xffu) * scale.z;
    vec4 hz = origin.z + vec4((uvec4(planes_z.y) >> shift) & 0xffu) * scale.z;
    vec4 ax = (lx - org.x) * inv_dir.x, bx = (hx - org.x) * inv_dir.x;
    vec4 ay = (ly - org.y) * inv_dir.y, by = (hy - org.y) * inv_dir.y;
    vec4 az = (lz - org.z) * inv_dir.z, bz = (hz - org.z) * inv_dir.z;
    vec4 enter = max(max(min(ax, bx), min(ay, by)), max(min(az, bz), vec4(tmin)));
    vec4 leave = min(min(max(ax, bx), max(ay, by)), max(az, bz)) * SLAB_SLACK;
    uvec4 meta = (uvec4(meta4) >> shift) & 0xffu;
    bvec4 reached = bvec4(uvec4(lessThanEqual(enter, leave)) & uvec4(lessThanEqual(enter, vec4(limit)))
                          & uvec4(notEqual(meta, uvec4(0u))));
    bvec4 interior = notEqual((uvec4(imask) >> slots) & 1u, uvec4(0u));
    uvec4 rank = uvec4(bitCount(uvec4(imask) & ((uvec4(1u) << slots) - 1u)));
    uvec4 leaf = BVH8_LEAF | ((bases.y + (meta & 0x1fu)) << 2u) | uvec4(bitCount(meta >> 5u));
    entry = mix(leaf, bases.x + rank, interior);
    key = mix(vec4(uintBitsToFloat(0x7f800000u)), enter, reached);
}

// Opens node `node`: its eight children in octant order (the k-th is slot octant ^ k), sorted by
// entry distance (Batcher's 19-comparator network, fovea_scene::bvh::compressed::SORT8) into
// e[0..8] nearest first; returns how many the ray reaches.
uint bvh8_open(uint node, vec3 org, vec3 inv_dir, float tmin, float limit, uint octant,
               out uvec4 e_lo, out uvec4 e_hi, out vec4 k_lo, out vec4 k_hi) {
    BVH_COUNT(1u, 0u, 0u, BVH8_NODE_BYTES);
    uint base = node * 5u;
    uvec4 n0 = bvh8_nodes.data[base], n1 = bvh8_nodes.data[base + 1u], n2 = bvh8_nodes.data[base + 2u];
    uvec4 n3 = bvh8_nodes.data[base + 3u], n4 = bvh8_nodes.data[base + 4u];
    vec3 origin = uintBitsToFloat(n0.xyz);
    vec3 scale = uintBitsToFloat(((uvec3(n0.w) >> uvec3(0u, 8u, 16u)) & 0xffu) << 23u);
    uint imask = n0.w >> 24u;
    // Words: n2 = lo.x (slots 0–3, 4–7), lo.y; n3 = lo.z, hi.x; n4 = hi.y, hi.z.
    vec4 key0, key1;
    uvec4 ent0, ent1;
    bvh8_half(uvec4(0u, 1u, 2u, 3u), uvec4(n2.x, n3.z, n2.z, n4.x), uvec4(n3.x, n4.z, 0u, 0u), n1.z,
              origin, scale, imask, n1.xy, org, inv_dir, tmin, limit, key0, ent0);
    bvh8_half(uvec4(4u, 5u, 6u, 7u), uvec4(n2.y, n3.w, n2.w, n4.y), uvec4(n3.y, n4.w, 0u, 0u), n1.w,
              origin, scale, imask, n1.xy, org, inv_dir, tmin, limit, key1, ent1);
    // Octant order: bit 2 swaps the halves, bit 1 the pairs, bit 0 neighbours (slot k ^ octant at k).
    bool s4 = (octant & 4u) != 0u, s2 = (octant & 2u) != 0u, s1 = (octant & 1u) != 0u;
    vec4 ka = s4 ? key1 : key0, kb = s4 ? key0 : key1;
    uvec4 ea = s4 ? ent1 : ent0, eb = s4 ? ent0 : ent1;
    ka = s2 ? ka.zwxy : ka; kb = s2 ? kb.zwxy : kb; ea = s2 ? ea.zwxy : ea; eb = s2 ? eb.zwxy : eb;
    ka = s1 ? ka.yxwz : ka; kb = s1 ? kb.yxwz : kb; ea = s1 ? ea.yxwz : ea; eb = s1 ? eb.yxwz : eb;
    float k0 = ka.x, k1 = ka.y, k2 = ka.z, k3 = ka.w, k4 = kb.x, k5 = kb.y, k6 = kb.z, k7 = kb.w;
    uint r0 = ea.x, r1 = ea.y, r2 = ea.z, r3 = ea.w, r4 = eb.x, r5 = eb.y, r6 = eb.z, r7 = eb.w;
    cswap(k0, r0, k1, r1); cswap(k2, r2, k3, r3); cswap(k4, r4, k5, r5); cswap(k6, r6, k7, r7);
    cswap(k0, r0, k2, r2); cswap(k1, r1, k3, r3); cswap(k4, r4, k6, r6); cswap(k5, r5, k7, r7);
    cswap(k1, r1, k2, r2); cswap(k5, r5, k6, r6); cswap(k0, r0, k4, r4); cswap(k3, r3, k7, r7);
    cswap(k1, r1, k5, r5); cswap(k2, r2, k6, r6); cswap(k1, r1, k4, r4); cswap(k3, r3, k6, r6);
    cswap(k2, r2, k4, r4); cswap(k3, r3, k5, r5); cswap(k3, r3, k4, r4);
    e_lo = uvec4(r0, r1, r2, r3);
    e_hi = uvec4(r4, r5, r6, r7);
    k_lo = vec4(k0, k1, k2, k3);
    k_hi = vec4(k4, k5, k6, k7);
    bvec4 miss_lo = isinf(k_lo), miss_hi = isinf(k_hi);
    return 8u - uint(miss_lo.x) - uint(miss_lo.y) - uint(miss_lo.z) - uint(miss_lo.w)
              - uint(miss_hi.x) - uint(miss_hi.y) - uint(miss_hi.z) - uint(miss_hi.w);
}

uint bvh8_octant(vec3 dir) {
    return (dir.x < 0.0 ? 4u : 0u) | (dir.y < 0.0 ? 2u : 0u) | (dir.z < 0.0 ? 1u : 0u);
}

// Pushes e[1 .. reached] farthest first (e[0] is visited next).
#define BVH8_PUSH_REST(stack, sp, size, reached, e_lo, e_hi, k_lo, k_hi) \
    if (reached > 7u && sp < size) stack[sp++] = uvec2(e_hi.w, floatBitsToUint(k_hi.w)); \
    if (reached > 6u && sp < size) stack[sp++] = uvec2(e_hi.z, floatBitsToUint(k_hi.z)); \
    if (reached > 5u && sp < size) stack[sp++] = uvec2(e_hi.y, floatBitsToUint(k_hi.y)); \
    if (reached > 4u && sp < size) stack[sp++] = uvec2(e_hi.x, floatBitsToUint(k_hi.x)); \
    if (reached > 3u && sp < size) stack[sp++] = uvec2(e_lo.w, floatBitsToUint(k_lo.w)); \
    if (reached > 2u && sp < size) stack[sp++] = uvec2(e_lo.z, floatBitsToUint(k_lo.z)); \
    if (reached > 1u && sp < size) stack[sp++] = uvec2(e_lo.y, floatBitsToUint(k_lo.y))

// Walks one compressed tree from `root` (as bvh_walk: closest or any hit, ids from id_base, alpha
// through TriangleGpu tri_base + k). Same algorithm as fovea_scene::bvh::compressed::Bvh8::walk.
bool bvh8_walk(uint root, vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, uint tri_base, uint id_base, inout Hit hit) {
    RayShear sh = ray_shear(org, dir);
    vec3 inv_dir = safe_inverse_dir(dir);
    uint octant = bvh8_octant(dir);
    uvec2 stack[BVH8_STACK_SIZE];
    int sp = 0;
    uint entry = root;
    bool have_entry = true;
    while (true) {
        float limit = hit.t * SLAB_SLACK;
        if (!have_entry) {
            // The nearest waiting entry not beyond the closest hit so far.
            bool found = false;
            while (sp > 0) {
                uvec2 e = stack[--sp];
                if (uintBitsToFloat(e.y) <= limit) { entry = e.x; found = true; break; }
            }
            if (!found) return false;
        }
        have_entry = false;
        if ((entry & BVH8_LEAF) != 0u) {
            uint first = (entry & ~BVH8_LEAF) >> 2u, count = entry & 3u;
            for (uint i = 0u; i < count; ++i) {
                BVH_COUNT(0u, 1u, 0u, BVH_TRIANGLE_BYTES);
                uint tb = (first + i) * 3u;
                vec4 t0 = bvh8_triangles.data[tb], t1 = bvh8_triangles.data[tb + 1u], t2 = bvh8_triangles.data[tb + 2u];
                uint k = floatBitsToUint(t0.w);
                uint id = id_base + k;
                vec3 tuv;
                if (intersect_triangle(sh, t0.xyz, t1.xyz, t2.xyz, tmin, tmax, tuv)
                    && (tuv.x < hit.t || (tuv.x == hit.t && id < hit.triangle))
                    && !alpha_cuts(floatBitsToUint(t1.w), tri_base + k, id, tuv.y, tuv.z)) {
                    hit.t = tuv.x;
                    hit.u = tuv.y;
                    hit.v = tuv.z;
                    hit.triangle = id;
                    if (any_hit) return true;
                }
            }
        } else {
            uvec4 e_lo, e_hi;
            vec4 k_lo, k_hi;
            uint reached = bvh8_open(entry, org, inv_dir, tmin, limit, octant, e_lo, e_hi, k_lo, k_hi);
            if (reached > 0u) {
                entry = e_lo.x;
                have_entry = true;
                BVH8_PUSH_REST(stack, sp, BVH8_STACK_SIZE, reached, e_lo, e_hi, k_lo, k_hi);
            }
        }
    }
    return false;
}

// The top level (frame.data.instancing.z its root): leaf entries hold instance indices (first
// component of the entry's first vec4), each instance reached walks its mesh's tree in object
// space. As fovea_scene::bvh::instanced::SceneBvh8::intersect.
bool instances8_walk(vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, inout Hit hit) {
    vec3 inv_dir = safe_inverse_dir(dir);
    uint octant = bvh8_octant(dir);
    uvec2 stack[BVH8_TOP_STACK_SIZE];
    int sp = 0;
    uint entry = frame.data.instancing.z;
    bool have_entry = true;
    while (true) {
        float limit = hit.t * SLAB_SLACK;
        if (!have_entry) {
            bool found = false;
            while (sp > 0) {
                uvec2 e = stack[--sp];
                if (uintBitsToFloat(e.y) <= limit) { entry = e.x; found = true; break; }
            }
            if (!found) return false;
        }
        have_entry = false;
        if ((entry & BVH8_LEAF) != 0u) {
            uint first = (entry & ~BVH8_LEAF) >> 2u, count = entry & 3u;
            for (uint i = 0u; i < count; ++i) {
                BVH_COUNT(0u, 0u, 0u, BVH_INSTANCE_BYTES);
                uint k = floatBitsToUint(bvh8_triangles.data[(first + i) * 3u].x);
                InstanceGpu inst = instances.data[k];
                vec3 o, d;
                to_object(inst, org, dir, o, d);
                if (bvh8_walk(inst.mesh.y, o, d, tmin, tmax, any_hit, inst.mesh.z, inst.mesh.x, hit)) return true;
            }
        } else {
            uvec4 e_lo, e_hi;
            vec4 k_lo, k_hi;
            uint reached = bvh8_open(entry, org, inv_dir, tmin, limit, octant, e_lo, e_hi, k_lo, k_hi);
            if (reached > 0u) {
                entry = e_lo.x;
                have_entry = true;
                BVH8_PUSH_REST(stack, sp, BVH8_TOP_STACK_SIZE, reached, e_lo, e_hi, k_lo, k_hi);
            }
        }
    }
    return false;
}
#endif // BVH_TRAVERSAL_GPU

// Closest hit (any_hit = false: smallest (t, placed id)) or the first hit found (shadow rays,
// any_hit = true) over the world tree and, when the scene has any, the instances.
bool bvh_trace(vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, out Hit hit) {
    hit.t = tmax;
    hit.triangle = 0xffffffffu;
    hit.u = 0.0;
    hit.v = 0.0;
#if defined(BVH_TRAVERSAL_GPU)
    if (!bvh8_walk(0u, org, dir, tmin, tmax, any_hit, 0u, 0u, hit) && frame.data.instancing.x != 0u) {
        instances8_walk(org, dir, tmin, tmax, any_hit, hit);
    }
#else
    if (!bvh_walk(0u, org, dir, tmin, tmax, any_hit, 0u, 0u, hit) && frame.data.instancing.x != 0u) {
        instances_walk(org, dir, tmin, tmax, any_hit, hit);
    }
#endif
    return hit.triangle != 0xffffffffu;
}

#endif
