"""An external renderer measured by the latency rig over Lab Streaming Layer: a template for yours.

It uses only pylsl, moderngl and glfw (for its window), nothing of the rig. It does what a Unity,
Unreal or C++ renderer does to be measured (README.md, "Measuring your own renderer over LSL"):

1. subscribe to the rig's `RigPose` stream: one pose per display frame, predicted for the instant in
   its `t_photon` channel, with the view the rig frames the pendulum with in the stream's
   description (`view/world_to_clip`, `view/sphere_radius_m`);
2. at every frame, draw a bright sphere (here a disc) at the newest pose;
3. after every buffer swap, publish a marker on `RigRendererMarkers`: the `frame` drawn (-1 before
   the first pose) and `t_swap`, the LSL time the swap returned, which is also the sample's stamp.

Run it, then `rig measure --renderer external ...`. `--pace-hz` paces swaps itself, for a virtual X
server (xvfb) that does not; on a real monitor vsync paces them and it is not needed.
"""

from __future__ import annotations

import argparse
import time

import glfw
import moderngl
import numpy as np
import pylsl

VERTEX = """
#version 330
in vec2 corner;
out vec2 ndc;
void main() { ndc = corner; gl_Position = vec4(corner, 0.0, 1.0); }
"""
FRAGMENT = """
#version 330
uniform vec2 centre;
uniform vec2 radius;
in vec2 ndc;
out vec4 colour;
void main() {
    vec2 d = (ndc - centre) / radius;
    colour = vec4(vec3(dot(d, d) <= 1.0 ? 1.0 : 0.0), 1.0);
}
"""


def open_pose_inlet(stream: pylsl.StreamInfo) -> tuple[pylsl.StreamInlet, np.ndarray, float]:
    """The rig's pose stream, with its world_to_clip (4x4) and sphere radius (m)."""
    inlet = pylsl.StreamInlet(stream, max_buflen=1)
    view = inlet.info(timeout=5.0).desc().child("view")
    world_to_clip = np.array([float(v) for v in view.child_value("world_to_clip").split()]).reshape(4, 4)
    return inlet, world_to_clip, float(view.child_value("sphere_radius_m"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pose", default="RigPose", help="the rig's pose stream (default: %(default)s)")
    parser.add_argument("--markers", default="RigRendererMarkers", help="the marker stream to publish (default: %(default)s)")
    parser.add_argument("--size", default="640x480", help="window size WIDTHxHEIGHT (default: %(default)s)")
    parser.add_argument("--position", default="0,0", help="window position X,Y (default: %(default)s)")
    parser.add_argument("--pace-hz", type=float, default=0.0, help="pace swaps at this rate (virtual X servers; default: vsync)")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))

    info = pylsl.StreamInfo(args.markers, "Markers", 2, 0.0, pylsl.cf_double64, f"external-renderer-{args.markers}")
    channels = info.desc().append_child("channels")
    for label, unit in (("frame", "count"), ("t_swap", "seconds")):
        channel = channels.append_child("channel")
        channel.append_child_value("label", label)
        channel.append_child_value("unit", unit)
    markers = pylsl.StreamOutlet(info)

    if not glfw.init():
        raise SystemExit("no display to open a window on")
    glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, 3)
    glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, 3)
    glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
    glfw.window_hint(glfw.RESIZABLE, False)
    window = glfw.create_window(width, height, "external renderer", None, None)
    glfw.set_window_pos(window, *(int(v) for v in args.position.split(",")))
    glfw.make_context_current(window)
    glfw.swap_interval(1)
    ctx = moderngl.create_context()
    program = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
    corners = ctx.buffer(np.array([-1, -1, 1, -1, -1, 1, 1, 1], dtype="f4").tobytes())
    quad = ctx.vertex_array(program, [(corners, "2f", "corner")])

    # Swap (and mark) from the start: the rig times this display by the markers before it publishes.
    resolver = pylsl.ContinuousResolver(prop="name", value=args.pose)
    frame, centre, radius = -1.0, (2.0, 2.0), (0.0, 0.0)
    inlet, world_to_clip = None, np.eye(4)
    next_swap = time.monotonic()
    while not glfw.window_should_close(window):
        glfw.poll_events()
        if inlet is None and (found := resolver.results()):
            inlet, world_to_clip, sphere_radius = open_pose_inlet(found[0])
            radius = (sphere_radius * world_to_clip[0, 0], sphere_radius * world_to_clip[1, 1])
        samples, _ = inlet.pull_chunk(timeout=0.0) if inlet is not None else ([], [])
        if samples:
            newest = samples[-1]
            frame = newest[0]
            clip = world_to_clip @ np.array([*newest[3:6], 1.0])
            centre = (clip[0] / clip[3], clip[1] / clip[3])
        program["centre"].value = centre
        program["radius"].value = radius
        ctx.clear(0.0, 0.0, 0.0)
        quad.render(moderngl.TRIANGLE_STRIP)
        if args.pace_hz > 0:
            next_swap += 1.0 / args.pace_hz
            time.sleep(max(0.0, next_swap - time.monotonic()))
        glfw.swap_buffers(window)
        ctx.finish()
        t_swap = pylsl.local_clock()
        markers.push_sample([frame, t_swap], t_swap)
    glfw.terminate()


if __name__ == "__main__":
    main()
