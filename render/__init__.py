"""Pictures of problems and plans: animated replays (GIF, MP4), contact sheets and scene images (PNG), an
interactive 3D replay (self-contained HTML), Gantt charts and task-graph drawings.

The layer reads checked problems, plan JSON and the geometry layer's models; nothing imports it but the
command line.  Each output format lives in its own leaf module, which alone imports its heavy library
(pybullet's TinyRenderer: :mod:`~mrgc.render.raster`; imageio: :mod:`~mrgc.render.video`; Pillow:
:mod:`~mrgc.render.picture`; viser: :mod:`~mrgc.render.html`; matplotlib: :mod:`~mrgc.render.gantt`).
docs/render.md describes what each picture shows and why.
"""
