"""The interactive material editor (``alight edit``): glfw window, imgui panel, live preview.

state.py holds plain data (no GL, no imgui); camera.py the orbit camera; panel.py draws the
imgui panel that edits that state; window.py owns the window, the GL context and the loop.
The ForwardRenderer draws the state and knows nothing of any of this.
"""
