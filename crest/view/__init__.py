"""The operator's browser view: live (`--view` on run, jog, move, demo) and replay (`crest view LOG.csv`).

A Bokeh server on 127.0.0.1 (view_server.py) serves one page (page.py) that draws ViewFrames
(view_frame.py), built from the control loop's samples (sample_slot.py, live_state.py) or from a
recorded log (replay_state.py). live_view.py ties a session to it, with the E-STOP button.
"""
