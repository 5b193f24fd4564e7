//! Statistics of world sets (filled in by the stats work).
