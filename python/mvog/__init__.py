"""Multi-Volume Occupancy Grids from Python: the mvog core (C++) as a numpy module.

Points are numpy arrays in the map frame, in metres; a volume's heights are in grid units
(z / resolution). ``mvog.msg`` and ``mvog.srv`` (the ROS messages and services) live in this
package too. See the README's section "Python".
"""

from mvog._mvog import *  # noqa: F401,F403 (the extension's names are the package's API)
