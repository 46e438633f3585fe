/* A replacement for MCML 1.2's RandomNum() (mcmlgo.c), used to test whether MCML's ran3
 * generator causes the difference in light skin's epidermal absorption between MCML and
 * multipole::montecarlo (docs/tests.md, "Light skin's epidermal absorption"). Paste it over
 * mcmlgo.c's RandomNum (and drop ran3's call in it); transport is left unchanged. The generator
 * is xoshiro256** (Blackman & Vigna), seeded by splitmix64 from the environment variable
 * MCML_SEED (default 1), returning 53-bit doubles in (0, 1).
 * Build: cc -O2 -o mcml-xoshiro mcmlmain.c mcmlgo.c mcmlio.c mcmlnr.c -lm
 * Run:   MCML_SEED=12345 ./mcml-xoshiro light-650.mci   (light-650.mci in this folder)
 */
#include <stdint.h>
#include <stdlib.h>

static uint64_t xs[4];

static uint64_t rotl(const uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static uint64_t splitmix(uint64_t *x)
{
  uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double RandomNum(void)
{
  static int first_time = 1;
  if (first_time) {
    const char *e = getenv("MCML_SEED");
    uint64_t s = e ? strtoull(e, 0, 10) : 1;
    for (int i = 0; i < 4; i++) xs[i] = splitmix(&s);
    first_time = 0;
  }
  const uint64_t result = rotl(xs[1] * 5, 7) * 9;
  const uint64_t t = xs[1] << 17;
  xs[2] ^= xs[0];
  xs[3] ^= xs[1];
  xs[1] ^= xs[2];
  xs[0] ^= xs[3];
  xs[2] ^= t;
  xs[3] = rotl(xs[3], 45);
  return ((result >> 11) + 0.5) * 0x1.0p-53;
}
