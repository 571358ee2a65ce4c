"""Camera frames to perception facts: saliency, colour, faces and head pose, ART2."""
