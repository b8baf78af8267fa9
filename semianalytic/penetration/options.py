"""Model choices the penetration commands offer (a leaf module: cheap to import for --help)."""

# lateral-compression energy W1 of Part I, eq. (28): closed forms in P (also in the vectorised curve)
W1_MODELS = ("neglect", "bound", "static")
