//! PLACEHOLDER: RON keyframe specs and frame generation — the pipeline helper writes this.
