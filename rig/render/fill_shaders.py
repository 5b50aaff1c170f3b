"""GLSL (3.3 core) of the warp server's passes after the warp: finding holes against a proxy map of
the scene (Smit et al. 2010, section 4.2.1) and filling what is left, from the farthest neighbour or
with a depth-aware low-pass pyramid (Schollmeyer et al., section 5.2). The warp itself is in
`rig.render.warp_shaders`.

Depths are window depths in [0, 1]; in the low-pass pyramid a depth of 2 marks a texel that holds
nothing (a hole).
"""

from __future__ import annotations

NEAREST_FILL_FRAGMENT_SHADER = """
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

PYRAMID_BASE_FRAGMENT_SHADER = """
#version 330
// Level 0 of the low-pass pyramid: (rgb, depth) of covered pixels, depth 2 for holes.
uniform sampler2D warped;
uniform sampler2D warped_depth;
out vec4 f_level;
void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(warped, texel, 0);
    f_level = c.a > 0.5 ? vec4(c.rgb, texelFetch(warped_depth, texel, 0).r) : vec4(0.0, 0.0, 0.0, 2.0);
}
"""

PYRAMID_REDUCE_FRAGMENT_SHADER = """
#version 330
// One level up the depth-aware low-pass pyramid: a texel averages the 2x2 texels below it that hold
// something and are not nearer than their mean depth, so foreground dissolves and holes are filled
// with what lies behind.
uniform sampler2D finer;
out vec4 f_level;
void main() {
    ivec2 size = textureSize(finer, 0);
    ivec2 base = ivec2(gl_FragCoord.xy) * 2;
    vec4 texels[4];
    float depth_sum = 0.0;
    float valid = 0.0;
    for (int i = 0; i < 4; ++i) {
        texels[i] = texelFetch(finer, min(base + ivec2(i & 1, i >> 1), size - 1), 0);
        if (texels[i].a < 1.5) {
            depth_sum += texels[i].a;
            valid += 1.0;
        }
    }
    if (valid == 0.0) {
        f_level = vec4(0.0, 0.0, 0.0, 2.0);
        return;
    }
    float mean_depth = depth_sum / valid;
    vec4 sum = vec4(0.0);
    float count = 0.0;
    for (int i = 0; i < 4; ++i) {
        if (texels[i].a < 1.5 && texels[i].a >= mean_depth - 1e-7) {
            sum += texels[i];
            count += 1.0;
        }
    }
    f_level = sum / count;
}
"""


LOWPASS_SEARCH_LEVELS = 2
"""Levels past the finest one that holds something in which a hole looks for a farther surface."""


def lowpass_fill_fragment_shader(levels: int) -> str:
    """The low-pass fill over pyramid levels 1..`levels` (samplers level_1 ...): a hole pixel takes
    the finest level whose bilinear neighbourhood holds something, or of it and the next
    LOWPASS_SEARCH_LEVELS the one whose sample lies farthest (a hole shows what lay behind: this
    looks past the foreground side of the hole for its background border), so the blur grows with
    the distance to that border; covered pixels pass through and alpha stays the hole mask."""
    samplers = "\n".join(f"uniform sampler2D level_{i};" for i in range(1, levels + 1))
    lookups = "\n".join(
        f"    if (found <= {LOWPASS_SEARCH_LEVELS} && sample_level(level_{i}, {float(2**i)!r}, sample)) {{\n"
        "        found += 1;\n"
        "        if (sample.a > fill.a) { fill = sample; }\n"
        "    } else if (found > 0) { found += 1; }"
        for i in range(1, levels + 1)
    )
    return f"""
#version 330
uniform sampler2D warped;
uniform vec3 background;
{samplers}
out vec4 f_colour;

// The texels of `level` (2^l pixels each) around the pixel centre, bilinear, weighted by whether
// they hold anything: (rgb, depth); false if none does.
bool sample_level(sampler2D level, float scale, out vec4 colour) {{
    vec2 at = (gl_FragCoord.xy) / scale - 0.5;
    ivec2 size = textureSize(level, 0);
    ivec2 base = ivec2(floor(at));
    vec2 f = at - vec2(base);
    vec4 sum = vec4(0.0);
    float depth = 0.0;
    for (int i = 0; i < 4; ++i) {{
        ivec2 corner = ivec2(i & 1, i >> 1);
        ivec2 texel = clamp(base + corner, ivec2(0), size - 1);
        vec4 v = texelFetch(level, texel, 0);
        float w = (corner.x == 1 ? f.x : 1.0 - f.x) * (corner.y == 1 ? f.y : 1.0 - f.y);
        if (v.a < 1.5 && w > 0.0) {{
            sum += vec4(v.rgb * w, w);
            depth += v.a * w;
        }}
    }}
    colour = sum.a > 0.0 ? vec4(sum.rgb / sum.a, depth / sum.a) : vec4(0.0);
    return sum.a > 0.0;
}}

void main() {{
    vec4 c = texelFetch(warped, ivec2(gl_FragCoord.xy), 0);
    if (c.a > 0.5) {{
        f_colour = c;
        return;
    }}
    vec4 fill = vec4(background, -1.0);
    vec4 sample;
    int found = 0;
{lookups}
    f_colour = vec4(fill.rgb, 0.0);
}}
"""


PROXY_VERTEX_SHADER = """
#version 330
// The proxy map (section 4.2.1): each object's bounding boxes (a kd-tree's leaves for the load, one
// box for the sphere), one instance a box, 36 vertices of its 12 triangles from gl_VertexID.
const int OBJECTS = %OBJECTS%;
uniform mat4 object_to_clip[OBJECTS];
in vec3 box_min;
in vec3 box_max;
in float box_object;
flat out float object_id;
// corner c is at (c & 1, c >> 1 & 1, c >> 2 & 1) of the box; triangles wind counter-clockwise
// seen from outside
const int CORNERS[36] = int[36](0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5, 0, 1, 4, 1, 5, 4,
                                2, 6, 3, 3, 6, 7, 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6);
void main() {
    int corner = CORNERS[gl_VertexID];
    vec3 p = mix(box_min, box_max, vec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1));
    int id = int(box_object + 0.5);
    gl_Position = object_to_clip[id] * vec4(p, 1.0);
    object_id = float(id);
}
"""

PROXY_FRAGMENT_SHADER = """
#version 330
uniform float id_scale;
flat in float object_id;
out float f_id;
void main() {
    f_id = object_id / id_scale;
}
"""

HOLE_FRAGMENT_SHADER = """
#version 330
// Hole levels (section 4.2.1) against the proxy map, up to max_level: 1 a level-0 hole (nothing
// warped) where a proxy says an object is; 2 a level-1 hole: another object warped here, behind the
// front of the proxy's; 3 a level-2 hole: the proxy's own object, but behind the back of the
// nearest proxy box, so a part of it is missing. 0 for everything else, background holes included:
// the fill redraws the background there. Which object hides which changes only where one moved
// since the client drew them (bit i of `moved`: object i's warp is not the static one), so level-1
// and level-2 holes are looked for only there.
uniform int moved;
uniform sampler2D warped;
uniform sampler2D warped_id;
uniform sampler2D warped_depth;
uniform sampler2D proxy_id;
uniform sampler2D proxy_depth;
uniform sampler2D proxy_back_depth;
uniform float id_scale;
uniform int max_level;
out vec4 f_hole;
void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    int proxy = int(texelFetch(proxy_id, texel, 0).r * id_scale + 0.5);
    float level = 0.0;
    if (proxy != 0) {
        bool covered = texelFetch(warped, texel, 0).a > 0.5;
        int id = int(texelFetch(warped_id, texel, 0).r * id_scale + 0.5);
        float depth = texelFetch(warped_depth, texel, 0).r;
        bool either_moved = ((moved >> proxy) & 1) == 1 || ((moved >> id) & 1) == 1;
        if (!covered) {
            level = 1.0;
        } else if (max_level >= 1 && either_moved && id != proxy && depth > texelFetch(proxy_depth, texel, 0).r) {
            level = 2.0;
        } else if (max_level >= 2 && either_moved && id == proxy && depth > texelFetch(proxy_back_depth, texel, 0).r) {
            level = 3.0;
        }
    }
    f_hole = vec4(level / 255.0, 0.0, 0.0, 1.0);
}
"""


def proxy_vertex_shader(object_count: int) -> str:
    return PROXY_VERTEX_SHADER.replace("%OBJECTS%", str(int(object_count)))
