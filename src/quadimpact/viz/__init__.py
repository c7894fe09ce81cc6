"""Pictures of a run: 3D snapshots, movies and an interactive HTML viewer.

* :mod:`quadimpact.viz.camera`: the camera and each command's default view;
* :mod:`quadimpact.viz.scene`: the geometry (NumPy; contact points from the
  compiled contact law);
* :mod:`quadimpact.viz.render`: the scene as matplotlib artists updated in place;
* :mod:`quadimpact.viz.snapshots`: ``snapshots.png``/``.pdf``;
* :mod:`quadimpact.viz.animation`: ``animation.mp4``/``.gif``;
* :mod:`quadimpact.viz.viewer`: ``viewer.html``;
* the commands ``quadimpact snapshots|animate|view`` are in :mod:`quadimpact.cli.viz_commands`.

Submodules are imported on demand (matplotlib and the compiled core are not
loaded by ``import quadimpact.viz``).
"""
