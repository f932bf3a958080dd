// Replaced by the sketch-map implementation (issue #4).
