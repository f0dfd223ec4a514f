"""Higashimori et al. 2007: the 2-step and 3-step friction-independent stick-capture strategies."""
