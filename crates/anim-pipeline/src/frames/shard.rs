//! One shard of an animation's frames, for spreading a render over machines or job arrays.
//! A shard is a contiguous run of frames, so that the frames of a shot (`super::shots`) stay
//! together and each is traced from the frame before it.

use std::fmt;
use std::str::FromStr;

/// One shard of an animation: K of N, K counting from 1 (as Slurm array task ids do).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

impl Shard {
    /// Whether frame `i` (counting from 0) of `n` belongs to this shard: the K-th of N
    /// contiguous runs, of as many frames as can be (⌊i·N/n⌋ = K − 1).
    pub fn contains(&self, i: usize, n: usize) -> bool {
        let (i, n, count) = (i as u128, n.max(1) as u128, self.count as u128);
        i * count / n == (self.index - 1) as u128
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = String;

    /// `K/N` with 1 ≤ K ≤ N.
    fn from_str(s: &str) -> Result<Shard, String> {
        let (k, n) = s.split_once('/').ok_or("expected K/N, e.g. 2/3")?;
        let index: u32 = k
            .trim()
            .parse()
            .map_err(|_| format!("'{k}' is not a whole number"))?;
        let count: u32 = n
            .trim()
            .parse()
            .map_err(|_| format!("'{n}' is not a whole number"))?;
        if count == 0 || index == 0 || index > count {
            return Err(format!("K must be between 1 and N (got {index}/{count})"));
        }
        Ok(Shard { index, count })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_frames_into_contiguous_runs() {
        let shards: Vec<Shard> = (1..=3).map(|k| format!("{k}/3").parse().unwrap()).collect();
        for n in [1, 2, 3, 10, 100] {
            let mut last = 0;
            for i in 0..n {
                let of: Vec<u32> = shards
                    .iter()
                    .filter(|s| s.contains(i, n))
                    .map(|s| s.index)
                    .collect();
                assert_eq!(of.len(), 1, "frame {i} of {n}");
                // In order, and no run longer than one more than another: ⌈n/3⌉ frames at most.
                assert!(of[0] >= last, "frame {i} of {n}");
                last = of[0];
                let run = (0..n).filter(|&j| shards[of[0] as usize - 1].contains(j, n));
                assert!(run.count() <= n.div_ceil(3), "frame {i} of {n}");
            }
        }
        for bad in ["0/3", "4/3", "1/0", "x/2", "3"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }
}
