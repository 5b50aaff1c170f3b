"""The self-test of `rig measure`: the whole live measurement with stand-ins for the bench (an
emulated tracker, a frame clock, a camera twin filming the window), run only by `--self-test`."""
