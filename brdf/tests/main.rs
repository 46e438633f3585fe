//! The Torrance–Sparrow lobe against its physics: sampling against its pdf, reciprocity, energy.

mod chi2;
mod lobe;
