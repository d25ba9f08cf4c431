//! PLACEHOLDER: `anim render DIR` (frames in parallel, skip-unchanged, shards) — the pipeline helper writes this.
