"""IPython start-up code of the kernels that execute the documentation's notebooks.

``docs/conf.py`` copies this file into the IPython profile of the build (``IPYTHONDIR`` in
``docs/_build``).  After every cell it checks each figure still open (the inline backend shows
and closes them just after): an axes that shows no data (``grazing.plotting.checks``) is
reported on stderr, which the build turns into a warning, hence an error (``-W``).
"""

import sys


def _check_figures(*_args):
    if "matplotlib.pyplot" not in sys.modules:
        return
    try:
        from matplotlib._pylab_helpers import Gcf

        from grazing.plotting.checks import empty_axes

        for manager in Gcf.get_all_fig_managers():
            for line in empty_axes(manager.canvas.figure):
                print(f"blank figure {manager.num}: {line}", file=sys.stderr)
    except Exception as exc:  # a check that cannot run is a failure too, never a silent pass
        print(f"the figure check failed: {exc!r}", file=sys.stderr)


get_ipython().events.register("post_execute", _check_figures)  # noqa: F821
