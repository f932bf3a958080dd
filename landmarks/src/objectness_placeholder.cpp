// Replaced by objectness (issue #5).
