"""spll-hw's own TDE and CCO as Lava Processes (:mod:`.process`) and their ProcessModels
(:mod:`.models_float`, tag ``floating_pt``; :mod:`.models_fixed`, tag ``fixed_pt``).

They live in a package of their own because Lava's compiler, for every Process it compiles,
imports every module of the Process's package and then executes every ``.py`` file beside it
as a top-level module, once per module of the package, to find ProcessModels (lava-nc 0.10,
``ProcGroupDiGraphs._find_proc_models``): beside the 20 modules of :mod:`mappings.lava` that
was about 400 executions per Process and run. The modules need lava-nc (the ``[lava]`` extra).
"""
