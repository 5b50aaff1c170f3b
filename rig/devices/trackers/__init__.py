"""Real trackers behind `rig.devices.protocols.TrackerSource`, chosen by spec in `rig.devices.registry`:

    serial:URL[?profile=NAME&baud=N]    a serial line or socket (serial_tracker), records per a profile
    hid:VID:PID[:PROFILE]               USB HID input reports (hid_tracker), laid out per a profile
    lsl:NAME                            a Lab Streaming Layer pose stream (lsl_tracker)

Each is a `TrackerStream` (stream.py) over a transport, which only moves bytes and stamps their
arrival on a reader thread (transport.py; compiled readers in _readers.c), and a decoder, which
turns them into readings and touches no device (decoders.py for profiles: TOML data in profile.py,
shipped ones in profiles/; lsl_tracker.py for LSL samples). The stream maps the device's time onto
the rig clock (clock_mapping.py), refuses impossible values (readings.py) and counts everything
(counters.py).
"""
