"""The rig's devices."""
