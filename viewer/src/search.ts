// SPDX-License-Identifier: MIT
// Binary search over time-ordered arrays (the recording's lines and snapshots, the agent trace).

/// The number of leading items whose key is <= value (keys non-decreasing).
export function countAtOrBefore<T>(items: readonly T[], key: (item: T) => number, value: number): number {
  let lo = 0;
  let hi = items.length;
  while (lo < hi) {
    const mid = (lo + hi) >>> 1;
    if (key(items[mid]) <= value) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/// The number of entries of the sorted array `ts` with t <= time.
export function upperBound(ts: readonly number[], time: number): number {
  return countAtOrBefore(ts, (t) => t, time);
}
