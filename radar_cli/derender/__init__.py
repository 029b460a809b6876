"""De-rendering photographs in batches: inputs, the model, exports (meshes, maps, renders), report, relighting."""
