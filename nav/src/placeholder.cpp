// Replaced by the navigation executive (issue #7).
