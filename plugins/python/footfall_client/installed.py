"""Where an installed footfall keeps libfootfall.so and footfalld, relative to this package.

`cmake --install` writes install_layout.py beside this file with the two paths relative to the
package's folder (share/footfall/python/footfall_client under the install prefix), so the
installed tree can move as a whole. In a source tree or the Blender zip there is no such file.
"""

import os

_HERE = os.path.dirname(os.path.abspath(__file__))


def installed_path(name):
    """The installed path of `name` ("lib" or "footfalld"), or None outside an install."""
    try:
        from . import install_layout  # pylint: disable=import-outside-toplevel
    except ImportError:
        return None
    relative = {"lib": install_layout.LIB, "footfalld": install_layout.FOOTFALLD}[name]
    return os.path.normpath(os.path.join(_HERE, relative))
