//! Leg kinematics and body-pose routines (Zucker 2011, §3.1–3.4). Being written.
