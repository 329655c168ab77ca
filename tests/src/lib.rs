//! yawcast-tests: cross-crate tests (host export → firmware native → firmware in QEMU).
