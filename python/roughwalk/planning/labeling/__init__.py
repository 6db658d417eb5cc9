"""The labelling web app: an expert judges pairs of footholds in a browser (Zucker 2011, §4.2).

Start it with ``roughwalk cost label --terrain T --store prefs.sqlite`` or from
Python::

    store = PreferenceStore.open("prefs.sqlite", create=True)
    session = LabelingSession(store, [load_terrain("round_rocks:seed=1")])
    server = LabelingServer(session)
    print(server.url)
    server.serve_forever()
"""

from roughwalk.planning.labeling.labeling_server import HOST, LabelingServer
from roughwalk.planning.labeling.labeling_session import (
    CHOICES,
    LabelingConfig,
    LabelingSession,
    StalePairError,
)

__all__ = [
    "HOST",
    "LabelingServer",
    "LabelingSession",
    "LabelingConfig",
    "StalePairError",
    "CHOICES",
]
