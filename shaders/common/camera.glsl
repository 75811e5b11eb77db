// Pinhole camera in tangent space (asymmetric per-eye FOVs allowed), Vulkan y-down pixels.
#ifndef FOVEA_CAMERA_GLSL
#define FOVEA_CAMERA_GLSL

// View-space direction (unnormalised, z = −1) through a screen position in pixels.
vec3 view_direction(vec2 screen, vec4 fov_tan, vec2 size) {
    vec2 f = screen / size;
    return vec3(mix(fov_tan.x, fov_tan.y, f.x), mix(fov_tan.w, fov_tan.z, f.y), -1.0);
}

// Screen position (pixels) of a view-space point; false behind the camera.
bool project_view(vec3 p, vec4 fov_tan, vec2 size, out vec2 screen) {
    screen = vec2(-1.0);
    if (p.z >= 0.0) return false;
    vec2 t = p.xy / -p.z;
    screen = vec2((t.x - fov_tan.x) / (fov_tan.y - fov_tan.x), (fov_tan.w - t.y) / (fov_tan.w - fov_tan.z)) * size;
    return true;
}

#endif
