"""De-rendering photographs, stage by stage: run (inputs, the network, batches and shares), refine (shape and
lighting fitted to the photograph), export (one object's folder: mesh, maps, renders, status) and present (the
report, the gallery and its server)."""
