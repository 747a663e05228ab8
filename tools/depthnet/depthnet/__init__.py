"""ademono's absolute depth network (ZoeDepth-style, log-binomial metric bins with bin splitting)."""
