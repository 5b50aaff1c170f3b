"""Settings declared once: each with its unit, range or choices, default, help and command-line
option, on the field of the frozen dataclass that holds it.

`predictors`, `analysis` and `rig` all declare what a user sets this way, and none of them may
import another's declarations, so the primitive lives here, importing nothing of the project:

* `Range` (`declared.ranges`): the numbers allowed, and how they read in a message;
* `setting(default, unit, help, range, flag=...)` declares a dataclass field (`declared.settings`);
  the dataclass's `__post_init__` calls `check(self, ErrorType)`, `like(kind, name)` holds the same
  setting in a second dataclass, and `walk(kind)` lists a config's settings, nested configs
  included, for the command line and the docs tables;
* `from_table(kind, table, ErrorType)` (`declared.tables`) reads a spec's table into the dataclass,
  every key and type checked;
* `declared.docs.markdown_table(kind)` is the docs' table of a config's settings.
"""

from declared.ranges import ANY, FRACTION, NON_NEGATIVE, OPEN_UNIT, POSITIVE, Range
from declared.settings import Entry, Flag, Setting, check, like, setting, setting_of, walk
from declared.tables import from_table, words

__all__ = [
    "ANY",
    "FRACTION",
    "NON_NEGATIVE",
    "OPEN_UNIT",
    "POSITIVE",
    "Entry",
    "Flag",
    "Range",
    "Setting",
    "check",
    "from_table",
    "like",
    "setting",
    "setting_of",
    "walk",
    "words",
]
