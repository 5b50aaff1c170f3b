"""The record profile a serial tracker reads unless told, light, so that the emulator's command line
can send in it by default without loading the readers (pyserial, the compiled readers)."""

SERIAL = "csv"
