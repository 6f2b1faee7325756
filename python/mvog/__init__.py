"""Multi-Volume Occupancy Grids from Python: the mvog core (C++) as a numpy module.

Points are numpy arrays in the map frame, in metres; a volume's heights are in grid units
(z / resolution). ``mvog.msg`` and ``mvog.srv`` (the ROS messages and services) live in this
package too. See the README's section "Python".

The extension (``mvog._mvog``) loads at the first use of one of its names, not at ``import
mvog``: a node that imports only ``mvog.msg`` or ``mvog.srv`` never loads the core's library
(a process that did not start with a sanitizer's runtime must not load a sanitized build of it).
"""

import importlib as _importlib


def _extension():
    return _importlib.import_module("mvog._mvog")


# The package's subpackages that catkin generates (messages, services, dynamic_reconfigure's
# config): `from mvog import srv` asks for them as attributes before importing them.
_GENERATED = ("msg", "srv", "cfg")


def __getattr__(name):
    """The extension's names, copied into the package at the first use of one."""
    if name in _GENERATED or name.startswith("__"):
        raise AttributeError("module 'mvog' has no attribute '%s'" % name)
    extension = _extension()
    public = {key: value for key, value in vars(extension).items() if not key.startswith("_")}
    globals().update(public)
    if name in public:
        return public[name]
    raise AttributeError("module 'mvog' has no attribute '%s'" % name)


def __dir__():
    return sorted(set(globals()) | {key for key in vars(_extension()) if not key.startswith("_")})
