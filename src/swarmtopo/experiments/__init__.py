"""Experiments on top of the pipeline: sweeps on Dask with a DuckDB result store, and
the paper's experiments reproduced (``swarmtopo sweep``, ``swarmtopo reproduce``)."""
