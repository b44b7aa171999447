// xoshiro256** (Blackman & Vigna 2018) seeded through splitmix64: small, fast,
// and defined by integer arithmetic alone, so every machine gets the same stream.
#include "plume/core.h"

static uint64_t splitmix64(uint64_t *state)
{
	uint64_t z = (*state += 0x9e3779b97f4a7c15ULL);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

plume_rng plume_rng_seed(uint64_t seed)
{
	plume_rng rng;
	for (int i = 0; i < 4; ++i)
		rng.s[i] = splitmix64(&seed);
	return rng;
}

uint64_t plume_rng_next(plume_rng *rng)
{
	uint64_t *s = rng->s;
	uint64_t result = rotl(s[1] * 5, 7) * 9;
	uint64_t t = s[1] << 17;
	s[2] ^= s[0];
	s[3] ^= s[1];
	s[1] ^= s[2];
	s[0] ^= s[3];
	s[2] ^= t;
	s[3] = rotl(s[3], 45);
	return result;
}

double plume_rng_uniform(plume_rng *rng) { return (double)(plume_rng_next(rng) >> 11) * 0x1.0p-53; }

double plume_rng_range(plume_rng *rng, double lo, double hi) { return lo + (hi - lo) * plume_rng_uniform(rng); }

plume_rng plume_rng_split(plume_rng *rng) { return plume_rng_seed(plume_rng_next(rng)); }
