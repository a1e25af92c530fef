"""Many inputs on a Dask cluster: ``track_many``."""
