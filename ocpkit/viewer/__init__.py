"""`ocpkit show`: a planned motion in 3D, interactive in the browser (viser) or as a GIF (matplotlib)."""
