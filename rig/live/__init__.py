"""Live runs: the session on the monotonic clock with real devices (`run`), measuring one with a
camera (`measure`), recording a camera (`record`), and the self-test's stand-ins (`selftest`)."""
