"""The RCL front end before the full-language work (see README.md): a
stand-alone package of verbatim copies, so the benchmark's baseline runs the
old code only."""
