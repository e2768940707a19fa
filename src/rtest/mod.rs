//! R-Test circle-test evaluation (paper section 2.3): read, normalise, fit EIJ.
