"""GLSL (3.3 core) of the warp renderer's client surface and of the server's warps: point and quad
splats, the pixel mesh, the adaptive grid. The scene's own shaders are in `rig.render.scene`, the
hole and fill passes in `rig.render.fill_shaders`.

Object IDs are stored normalised in a 16-bit channel (R16), id / 65535, as the seeds store 16-bit
IDs: a normalised format clears and renders like any colour, where an integer one would not. A warp
writes the colour (alpha 1: something was warped here) and the object ID of what it warped.
"""

from __future__ import annotations

ID_SCALE = 65535.0
"""Object ID i is stored as i / ID_SCALE in the client's R16 ID texture."""

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

_SPLAT = """Splat {
    vec4 colour;  // rgb, and the object id in alpha
    vec2 half_x;  // clip-space offset of half a client pixel along client x, after the warp
    vec2 half_y;
}"""
"""The interface block a splat carries from the vertex to the fragment shader."""

_WARP_HEADER = """
#version 330
// P' = M_id (x, y, z, 1): client pixel (i, j) in OpenGL rows (j = 0 at the bottom), at NDC (x, y)
// with NDC depth z, moved by its object's warp matrix M_id.
const int OBJECTS = %OBJECTS%;
uniform mat4 warp_matrices[OBJECTS];
uniform sampler2D client_colour;
uniform sampler2D client_surface;  // (NDC depth, depth slope x, depth slope y, object id)
uniform ivec2 client_size;
uniform float background_ndc_z;

int object_of(vec4 surface) {
    return clamp(int(surface.w + 0.5), 0, OBJECTS - 1);
}

vec2 pixel_ndc(vec2 pixel) {
    return pixel / vec2(client_size) * 2.0 - 1.0;
}

// The client pixel of this vertex, one vertex per pixel in row order.
ivec2 vertex_texel() {
    return ivec2(gl_VertexID % client_size.x, gl_VertexID / client_size.x);
}

// The warped clip position of a client surface point at `ndc` (depth z) of object `id`.
vec4 warped(int id, vec2 ndc, float z) {
    vec4 p = warp_matrices[id] * vec4(ndc, z, 1.0);
    if (id == 0) {
        p.z = background_ndc_z * p.w;  // the background stays just inside the far plane
    }
    if (!(p.w > 0.0)) {
        p = vec4(0.0, 0.0, 2.0, 1.0);  // behind the server's eye: outside the clip volume
    }
    return p;
}
"""

_SPLAT_VERTEX_MAIN = f"""
// One vertex per client pixel, from gl_VertexID; the splat covers the warped pixel.
uniform vec2 server_size;
uniform float max_splat;
uniform float splat_rounding;

out {_SPLAT} splat;
""" + """
void main() {
    ivec2 texel = vertex_texel();
    vec4 surface = texelFetch(client_surface, texel, 0);
    int id = object_of(surface);
    mat4 m = warp_matrices[id];
    vec2 ndc = pixel_ndc(vec2(texel) + 0.5);
    vec4 p = m * vec4(ndc, surface.x, 1.0);
    // Jacobian of the warp after the homogeneous division (Smit et al. 2010, section 3.4)
    vec4 dpx = m[0] + m[2] * surface.y;
    vec4 dpy = m[1] + m[2] * surface.z;
    vec2 jx = (p.w * dpx.xy - p.xy * dpx.w) / (p.w * p.w);
    vec2 jy = (p.w * dpy.xy - p.xy * dpy.w) / (p.w * p.w);
    vec2 extent = (abs(jx) / float(client_size.x) + abs(jy) / float(client_size.y)) * server_size;
    gl_PointSize = clamp(ceil(max(extent.x, extent.y) - splat_rounding), 1.0, max_splat);
    p = warped(id, ndc, surface.x);
    gl_Position = p;
    splat.colour = vec4(texelFetch(client_colour, texel, 0).rgb, float(id));
    splat.half_x = jx / float(client_size.x) * p.w;
    splat.half_y = jy / float(client_size.y) * p.w;
}
"""

_MESH_VERTEX_MAIN = """
// One vertex per client pixel centre; triangles of neighbouring pixels are drawn by index.
out Vertex {
    vec4 colour;  // rgb, and the object id in alpha
} vertex;

void main() {
    ivec2 texel = vertex_texel();
    vec4 surface = texelFetch(client_surface, texel, 0);
    int id = object_of(surface);
    gl_Position = warped(id, pixel_ndc(vec2(texel) + 0.5), surface.x);
    vertex.colour = vec4(texelFetch(client_colour, texel, 0).rgb, float(id));
}
"""

_GRID_VERTEX_MAIN = """
// One instance per grid cell (x, y, side in client pixels), drawn as a 4-vertex strip. A cell is a
// flat patch of one object: each corner's depth follows the plane of the cell's pixel beside it.
in ivec3 cell;
out vec2 client_pixel;
flat out ivec4 cell_bounds;
flat out float object_id;

void main() {
    ivec2 corner = ivec2(gl_VertexID & 1, gl_VertexID >> 1);
    ivec2 inside = cell.xy + corner * (cell.z - 1);
    vec4 surface = texelFetch(client_surface, inside, 0);
    int id = object_of(texelFetch(client_surface, cell.xy, 0));
    vec2 offset = (vec2(corner) - 0.5) * 2.0 / vec2(client_size);
    float z = surface.x + dot(surface.yz, offset);
    vec2 pixel = vec2(cell.xy + corner * cell.z);
    gl_Position = warped(id, pixel_ndc(pixel), z);
    client_pixel = pixel;
    cell_bounds = ivec4(cell.xy, cell.xy + cell.z - 1);
    object_id = float(id);
}
"""

WARP_QUAD_GEOMETRY_SHADER = f"""
#version 330
// Quad splat: the warped pixel's parallelogram, corners at P' +- half_x +- half_y (section 4.1).
layout(points) in;
layout(triangle_strip, max_vertices = 4) out;
in {_SPLAT} splat_in[];
out {_SPLAT} splat;
""" + """
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

WARP_MESH_GEOMETRY_SHADER = """
#version 330
// Mesh reconstruction (section 4.1): the client pixels as one connected triangle mesh, as the seed
// draws it, except between objects that move apart: a triangle whose pixels belong to objects with
// different warps (motion_class) would stretch a rubber sheet across their silhouette; it is dropped
// and leaves a hole for the fill. Within one motion the warp maps pixel centres onto the vertices,
// so an unmoved part of the mesh reproduces the client image exactly.
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
uniform int motion_class[%OBJECTS%];
in Vertex {
    vec4 colour;
} vertex[];
out %SPLAT% splat;
int motion_of(int i) {
    return motion_class[int(vertex[i].colour.a + 0.5)];
}
void main() {
    if (motion_of(1) != motion_of(0) || motion_of(2) != motion_of(0)) {
        return;
    }
    for (int i = 0; i < 3; ++i) {
        gl_Position = gl_in[i].gl_Position;
        splat.colour = vertex[i].colour;
        splat.half_x = vec2(0.0);
        splat.half_y = vec2(0.0);
        EmitVertex();
    }
    EndPrimitive();
}
""".replace("%SPLAT%", _SPLAT)


def mesh_geometry_shader(object_count: int) -> str:
    """WARP_MESH_GEOMETRY_SHADER for a scene of `object_count` objects."""
    return WARP_MESH_GEOMETRY_SHADER.replace("%OBJECTS%", str(int(object_count)))

_COVERAGE_TEST = """
uniform float id_scale;
uniform sampler2D coverage;  // a first view's warp: alpha 1 where it covered the pixel
uniform bool arbitrate;      // true: this view may only fill the first view's holes
layout(location = 0) out vec4 f_colour;  // alpha 1: something warped here
layout(location = 1) out float f_id;

void write(vec3 colour, float id) {
    if (arbitrate && texelFetch(coverage, ivec2(gl_FragCoord.xy), 0).a > 0.5) {
        discard;
    }
    f_colour = vec4(colour, 1.0);
    f_id = floor(id + 0.5) / id_scale;
}
"""

WARP_FRAGMENT_SHADER = (
    f"""
#version 330
in {_SPLAT} splat;
"""
    + _COVERAGE_TEST
    + """
void main() {
    write(splat.colour.rgb, splat.colour.a);
}
"""
)

GRID_FRAGMENT_SHADER = (
    """
#version 330
// A grid cell's colour: the client texel under the fragment, nearest, never outside the cell.
uniform sampler2D client_colour;
in vec2 client_pixel;
flat in ivec4 cell_bounds;
flat in float object_id;
"""
    + _COVERAGE_TEST
    + """
void main() {
    ivec2 texel = clamp(ivec2(floor(client_pixel)), cell_bounds.xy, cell_bounds.zw);
    write(texelFetch(client_colour, texel, 0).rgb, object_id);
}
"""
)


def warp_vertex_shader(reconstruction: str, object_count: int) -> str:
    """The warp's vertex shader for a reconstruction ("point", "quad", "mesh", "grid") and a scene
    of `object_count` objects (IDs 0 to object_count - 1)."""
    main = {"point": _SPLAT_VERTEX_MAIN, "quad": _SPLAT_VERTEX_MAIN, "mesh": _MESH_VERTEX_MAIN, "grid": _GRID_VERTEX_MAIN}[reconstruction]
    return _WARP_HEADER.replace("%OBJECTS%", str(int(object_count))) + main
