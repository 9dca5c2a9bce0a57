"""Facts → collaborative manipulation task graph (CMTG) → SkeletonModel IR (see docs/architecture.md)."""
