//! Packing a rubric with its scene files and goldens, for the Gradescope autograder.
