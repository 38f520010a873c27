"""Files: video frames with timestamps, tracks and repertoire HDF5 files, atomic outputs."""
