//! The cosdem worker: disc DEM assemblies, one per Gauss point.
