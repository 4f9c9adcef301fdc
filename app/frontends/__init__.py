"""The ways in: ``cli`` (the ``alight`` command), ``api`` (``alight.Renderer``), ``batch`` with
``batch_worker`` and ``batch_ray``, ``pytest_plugin`` and the ``editor``. Front ends import the
rest; nothing below imports a front end."""
