"""How right the renderer is, and spending no more than a scene needs: ``ground_truth``
(docs/conventions.md's exact answer in numpy), ``reference`` (the same on the GPU,
``shaders/accuracy/``), ``converged`` (the numpy twins of every IBL model with converged maps),
``metrics`` (relMAE, FLIP, heat maps), ``chart`` and ``chart_plot`` (error against time) and
``auto_quality`` (the cheapest bake within an error budget, from a measured table)."""
