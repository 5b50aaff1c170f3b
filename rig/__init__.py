"""The latency rig application: devices (real and simulated), renderers, sessions, the `rig` CLI."""
