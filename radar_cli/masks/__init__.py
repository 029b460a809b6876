"""Photographs -> square training crops with silhouettes: detect, refine (GrabCut), crop, score, write."""
