//! Signed distance fields of terrain (Zucker 2011, §3.3). Being written.
