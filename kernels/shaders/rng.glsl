// Counter-based random numbers, the twin of kernels/ray_gen.cpp: 64-bit integer arithmetic, so
// every key and uniform is bit-identical to the CPU's.
uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15UL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9UL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBUL;
  return x ^ (x >> 31);
}
// kernels::rng_hash: the key of (seed, probe, pass, ray).
uint64_t rng_hash(uint64_t seed, uint64_t probe, uint64_t pass, uint64_t ray) {
  uint64_t h = splitmix64(seed);
  h = splitmix64(h ^ probe);
  h = splitmix64(h ^ pass);
  return splitmix64(h ^ ray);
}
float rng_uniform(uint64_t key, uint stream) {
  uint64_t h = splitmix64(key ^ (0xD1B54A32D192ED03UL * (uint64_t(stream) + 1UL)));
  return float(uint(h >> 40)) * (1.0 / 16777216.0);
}
