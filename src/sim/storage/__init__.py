"""The run file: the H5MD writer, the checks and summary of ``sim-inspect``, and the export to
GSD and XYZ for other tools."""
