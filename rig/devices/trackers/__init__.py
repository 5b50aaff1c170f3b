"""Real trackers behind `rig.devices.protocols.TrackerSource`, chosen by spec in `rig.devices.registry`:

    serial:URL[?profile=NAME&baud=N]    a serial line or socket (serial_tracker), records per a profile
    hid:VID:PID[:PROFILE]               USB HID input reports (hid_tracker), laid out per a profile
    lsl:NAME                            a Lab Streaming Layer pose stream (lsl_tracker)

Each is a `TrackerStream` (stream.py): a link read on its own thread, the device's time mapped onto
the rig clock (clock_mapping.py), impossible values refused (readings.py), everything counted
(counters.py). Record formats are data: profiles (profile.py, shipped ones in profiles/) read by
the decoders (decoders.py).
"""
