"""GLSL (3.3 core) of the warp renderer: the client's object-ID outputs, the per-pixel warp, the hole fill.

Object IDs are stored normalised in a 16-bit channel (R16), id / 65535, as the seeds store 16-bit
IDs: a normalised format clears and renders like any colour, where an integer one would not.
"""

from __future__ import annotations

ID_SCALE = 65535.0
"""Object ID i is stored as i / ID_SCALE in the client's R16 ID texture."""

CLIENT_SPHERE_FRAGMENT_SHADER = """
#version 330
uniform vec4 eye;
uniform float ambient;
uniform float diffuse;
uniform float object_id;
in vec3 v_world;
in vec3 v_normal;
layout(location = 0) out vec4 f_colour;
layout(location = 1) out float f_id;
void main() {
    vec3 to_eye = normalize(eye.xyz - eye.w * v_world);
    float lit = ambient + diffuse * max(dot(normalize(v_normal), to_eye), 0.0);
    f_colour = vec4(vec3(lit), 1.0);
    f_id = object_id;
}
"""

CLIENT_LOAD_VERTEX_SHADER = """
#version 330
uniform mat4 object_to_clip;
uniform float max_intensity;
uniform vec2 depth_range;
in vec3 in_ndc;
out float v_intensity;
void main() {
    v_intensity = max_intensity * (depth_range.y - in_ndc.z) / (depth_range.y - depth_range.x);
    gl_Position = object_to_clip * vec4(in_ndc, 1.0);
}
"""

CLIENT_LOAD_FRAGMENT_SHADER = """
#version 330
uniform float object_id;
in float v_intensity;
layout(location = 0) out vec4 f_colour;
layout(location = 1) out float f_id;
void main() {
    f_colour = vec4(vec3(v_intensity), 1.0);
    f_id = object_id;
}
"""

SURFACE_FRAGMENT_SHADER = """
#version 330
// Once per client frame: what the warp needs of each pixel's surface, in one RGBA32F texel:
// (NDC depth, d depth / d NDC x, d depth / d NDC y, object id). A slope is the smaller one-sided
// difference to a neighbour showing the same object (robust at depth edges, where the central
// difference would explode), 0 if neither neighbour does or the pixel is background (id 0).
uniform sampler2D client_id;
uniform sampler2D client_depth;
uniform float id_scale;
out vec4 f_surface;

int object_at(ivec2 texel) {
    return int(texelFetch(client_id, texel, 0).r * id_scale + 0.5);
}

float ndc_depth(ivec2 texel) {
    return texelFetch(client_depth, texel, 0).r * 2.0 - 1.0;
}

float depth_slope(ivec2 texel, ivec2 step, int id, float z, ivec2 size) {
    ivec2 before = clamp(texel - step, ivec2(0), size - 1);
    ivec2 after = clamp(texel + step, ivec2(0), size - 1);
    bool has_before = before != texel && object_at(before) == id;
    bool has_after = after != texel && object_at(after) == id;
    float d_before = z - ndc_depth(before);
    float d_after = ndc_depth(after) - z;
    float best = has_before && (!has_after || abs(d_before) <= abs(d_after)) ? d_before : (has_after ? d_after : 0.0);
    return best * float(step.x * size.x + step.y * size.y) / 2.0;
}

void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(client_depth, 0);
    int id = object_at(texel);
    float z = ndc_depth(texel);
    vec2 slope = vec2(0.0);
    if (id != 0) {
        slope = vec2(depth_slope(texel, ivec2(1, 0), id, z, size), depth_slope(texel, ivec2(0, 1), id, z, size));
    }
    f_surface = vec4(z, slope, float(id));
}
"""

WARP_VERTEX_SHADER = """
#version 330
// One vertex per client pixel, pixel (i, j) = (gl_VertexID % width, gl_VertexID / width), OpenGL
// rows (j = 0 at the bottom). P' = M_id (x, y, z, 1) with the object's warp matrix M_id.
const int OBJECTS = %OBJECTS%;
uniform mat4 warp_matrices[OBJECTS];
uniform sampler2D client_colour;
uniform sampler2D client_surface;  // (NDC depth, depth slope x, depth slope y, object id)
uniform ivec2 client_size;
uniform vec2 server_size;
uniform float max_splat;
uniform float splat_rounding;
uniform float background_ndc_z;

out Splat {
    vec4 colour;
    vec2 half_x;  // clip-space offset of half a client pixel along client x, after the warp
    vec2 half_y;
} splat;

void main() {
    ivec2 texel = ivec2(gl_VertexID % client_size.x, gl_VertexID / client_size.x);
    vec4 surface = texelFetch(client_surface, texel, 0);
    int id = clamp(int(surface.w + 0.5), 0, OBJECTS - 1);
    mat4 m = warp_matrices[id];
    vec2 ndc = (vec2(texel) + 0.5) / vec2(client_size) * 2.0 - 1.0;
    vec4 p = m * vec4(ndc, surface.x, 1.0);
    // Jacobian of the warp after the homogeneous division (Smit et al. 2010, section 3.4)
    vec4 dpx = m[0] + m[2] * surface.y;
    vec4 dpy = m[1] + m[2] * surface.z;
    vec2 jx = (p.w * dpx.xy - p.xy * dpx.w) / (p.w * p.w);
    vec2 jy = (p.w * dpy.xy - p.xy * dpy.w) / (p.w * p.w);
    vec2 extent = (abs(jx) / float(client_size.x) + abs(jy) / float(client_size.y)) * server_size;
    gl_PointSize = clamp(ceil(max(extent.x, extent.y) - splat_rounding), 1.0, max_splat);
    if (id == 0) {
        p.z = background_ndc_z * p.w;  // the background stays just inside the far plane
    }
    if (!(p.w > 0.0)) {
        p = vec4(0.0, 0.0, 2.0, 1.0);  // behind the server's eye: outside the clip volume
    }
    gl_Position = p;
    splat.colour = vec4(texelFetch(client_colour, texel, 0).rgb, 1.0);
    splat.half_x = jx / float(client_size.x) * p.w;
    splat.half_y = jy / float(client_size.y) * p.w;
}
"""


def warp_vertex_shader(object_count: int) -> str:
    """WARP_VERTEX_SHADER for a scene of `object_count` objects (IDs 0 to object_count - 1)."""
    return WARP_VERTEX_SHADER.replace("%OBJECTS%", str(int(object_count)))


WARP_QUAD_GEOMETRY_SHADER = """
#version 330
// Quad splat: the warped pixel's parallelogram, corners at P' +- half_x +- half_y (section 4.1).
layout(points) in;
layout(triangle_strip, max_vertices = 4) out;
in Splat {
    vec4 colour;
    vec2 half_x;
    vec2 half_y;
} splat_in[];
out Splat {
    vec4 colour;
    vec2 half_x;
    vec2 half_y;
} splat;
void main() {
    vec4 p = gl_in[0].gl_Position;
    for (int corner = 0; corner < 4; ++corner) {
        float sx = (corner % 2 == 0) ? -1.0 : 1.0;
        float sy = (corner < 2) ? -1.0 : 1.0;
        gl_Position = p + vec4(sx * splat_in[0].half_x + sy * splat_in[0].half_y, 0.0, 0.0);
        splat.colour = splat_in[0].colour;
        splat.half_x = splat_in[0].half_x;
        splat.half_y = splat_in[0].half_y;
        EmitVertex();
    }
    EndPrimitive();
}
"""

WARP_FRAGMENT_SHADER = """
#version 330
in Splat {
    vec4 colour;
    vec2 half_x;
    vec2 half_y;
} splat;
out vec4 f_colour;  // alpha 1: something warped here
void main() {
    f_colour = splat.colour;
}
"""

FULLSCREEN_VERTEX_SHADER = """
#version 330
// One triangle covering the viewport, from gl_VertexID 0, 1, 2.
void main() {
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
"""

FILL_FRAGMENT_SHADER = """
#version 330
// A level-0 hole (nothing warped here, alpha 0) shows what lay behind what moved: from the first
// covered pixel in each of 8 directions (up to max_steps away) it takes the farthest one's colour.
// Covered pixels pass through; alpha stays the hole mask.
uniform sampler2D warped;
uniform sampler2D warped_depth;
uniform int max_steps;
uniform vec3 background;
out vec4 f_colour;
const ivec2 DIRECTIONS[8] = ivec2[8](
    ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1),
    ivec2(1, 1), ivec2(-1, 1), ivec2(1, -1), ivec2(-1, -1));
void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(warped, texel, 0);
    if (c.a > 0.5) {
        f_colour = c;
        return;
    }
    ivec2 size = textureSize(warped, 0);
    float farthest = -1.0;
    vec3 fill = background;
    for (int d = 0; d < 8; ++d) {
        for (int step = 1; step <= max_steps; ++step) {
            ivec2 n = texel + DIRECTIONS[d] * step;
            if (any(lessThan(n, ivec2(0))) || any(greaterThanEqual(n, size))) {
                break;
            }
            vec4 v = texelFetch(warped, n, 0);
            if (v.a > 0.5) {
                float depth = texelFetch(warped_depth, n, 0).r;
                if (depth > farthest) {
                    farthest = depth;
                    fill = v.rgb;
                }
                break;
            }
        }
    }
    f_colour = vec4(fill, 0.0);
}
"""
