/* Random-force schedules: Rm * z_j, z_j ~ N(0,1), drawn lazily in order from
 * a GSL Mersenne Twister seeded per (experiment seed, group, trial). */
#include "beamsim/schedule.h"
#include "model/schedule_spare.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

struct bsim_schedule {
	gsl_rng *rng;
	double magnitude; /* N */
	double frequency; /* Hz */
	double *z;        /* standard-normal values drawn so far */
	long n_drawn, cap;
	unsigned long draws;
	unsigned long counted; /* draws already added to total_draws */
	/* The value held over steps [held_lo, held_hi) at step h (s), so that
	 * a step inside the hold reads it without computing its index. */
	long held_lo, held_hi;
	double held_h, held_value;
	long held_j; /* the index of the value held */
	long failed; /* 0, or the index that could not be given a value */
	int oom;     /* 1: failed for want of memory; 0: beyond any schedule */
};

static unsigned long total_draws;

/* No schedule grows to this many values (2^40 doubles, 8 TB), so cap
 * doubling below never overflows. */
#define SCHEDULE_MAX (1L << 40)

/* SplitMix64's finaliser (Steele, Lea & Flood 2014): a bijection with full
 * avalanche, applied to each input in turn so that nearby (g, t) pairs get
 * unrelated streams. */
static uint64_t splitmix64(uint64_t z)
{
	z += 0x9e3779b97f4a7c15ULL;
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

uint64_t bsim_schedule_seed_mix(uint64_t seed, uint64_t group, uint64_t trial)
{
	uint64_t h = splitmix64(seed);
	h = splitmix64(h ^ group);
	return splitmix64(h ^ trial);
}

bsim_schedule *bsim_schedule_alloc(double magnitude, double frequency, uint64_t seed)
{
	bsim_schedule *s = calloc(1, sizeof *s);
	if (!s)
		return NULL;
	s->rng = gsl_rng_alloc(gsl_rng_mt19937);
	if (!s->rng) {
		free(s);
		return NULL;
	}
	bsim_schedule_restart(s, magnitude, frequency, seed);
	return s;
}

void bsim_schedule_restart(bsim_schedule *s, double magnitude, double frequency, uint64_t seed)
{
	s->frequency = frequency;
	bsim_schedule_reset(s, magnitude, seed);
}

/* The draws of s not yet in total_draws go there: once per trial, not per
 * draw, so threads do not share a counter's cache line every few steps. */
static void schedule_count(bsim_schedule *s)
{
	__atomic_fetch_add(&total_draws, s->draws - s->counted, __ATOMIC_RELAXED);
	s->counted = s->draws;
}

void bsim_schedule_keep(bsim_schedule *s)
{
	schedule_count(s);
}

void bsim_schedule_free(bsim_schedule *s)
{
	if (!s)
		return;
	schedule_count(s);
	gsl_rng_free(s->rng);
	free(s->z);
	free(s);
}

void bsim_schedule_reset(bsim_schedule *s, double magnitude, uint64_t seed)
{
	/* gsl_rng_set takes an unsigned long (64 bits here); MT19937 uses its
	 * low 32 bits, so fold the high half in. */
	schedule_count(s);
	gsl_rng_set(s->rng, (unsigned long)(seed ^ (seed >> 32)));
	s->magnitude = magnitude;
	s->n_drawn = 0;
	s->draws = 0;
	s->counted = 0;
	s->held_lo = s->held_hi = 0;
	s->failed = 0;
	s->oom = 0;
}

long bsim_schedule_hold_steps(const bsim_schedule *s, double h)
{
	double per = 1.0 / (s->frequency * h);
	double whole = nearbyint(per);
	if (whole >= 1.0 && whole < 1e15 && fabs(per - whole) <= 1e-9 * per)
		return (long)whole;
	return 0;
}

long bsim_schedule_index(const bsim_schedule *s, long n, double h)
{
	/* Value j applies on [j/f, (j+1)/f). When 1/(f h) is a whole number of
	 * steps use integer division, so that rounding of n*h*f never moves a
	 * refresh by a step. */
	long whole = bsim_schedule_hold_steps(s, h);
	if (whole)
		return n / whole;
	/* Validation keeps the index small (bsim_limits schedule); a scene
	 * built in code may not, and converting a double beyond long's range
	 * is undefined: such an index is past any schedule that can be drawn. */
	double j = floor((double)n * h * s->frequency);
	return j < SCHEDULE_MAX ? (long)j : SCHEDULE_MAX;
}

/* The value of index j, drawn if it is the next: bsim_schedule_value, its
 * common case without a call. */
static inline double schedule_value_at(bsim_schedule *s, long j)
{
	if (j >= 0 && j < s->n_drawn)
		return s->magnitude * s->z[j];
	if (j == s->n_drawn && j < s->cap) {
		s->z[s->n_drawn++] = gsl_ran_gaussian_ziggurat(s->rng, 1.0);
		s->draws++;
		return s->magnitude * s->z[j];
	}
	return bsim_schedule_value(s, j);
}

double bsim_schedule_at_step(bsim_schedule *s, long n, double h)
{
	if (n >= s->held_lo && n < s->held_hi && h == s->held_h)
		return s->held_value;
	long whole, j;
	if (n == s->held_hi && h == s->held_h && s->held_hi > s->held_lo) {
		/* The hold after the one held (steps in order): the same h, so
		 * the same whole, and n / whole is the held index + 1. */
		whole = s->held_hi - s->held_lo;
		j = s->held_j + 1;
	} else {
		whole = bsim_schedule_hold_steps(s, h);
		j = whole ? n / whole : bsim_schedule_index(s, n, h);
	}
	double value = schedule_value_at(s, j);
	if (whole && !s->failed && n >= 0 && n < LONG_MAX - whole) {
		s->held_lo = j * whole;
		s->held_hi = s->held_lo + whole;
		s->held_h = h;
		s->held_value = value;
		s->held_j = j;
	}
	return value;
}

double bsim_schedule_at_step_held(bsim_schedule *s, long n, double h, long held[2])
{
	/* The hold after the one held, its value the next to draw (a trial's
	 * steps in order): what bsim_schedule_at_step does then, in a few
	 * operations, and the hold it sets (n / whole = held_j + 1, whole
	 * the same for the same h; its value drawn, no failure before). */
	const long whole = s->held_hi - s->held_lo, j = s->held_j + 1;
	if (n == s->held_hi && h == s->held_h && whole > 0 && j == s->n_drawn && j < s->cap &&
	    !s->failed && n < LONG_MAX - whole) {
		s->z[s->n_drawn++] = gsl_ran_gaussian_ziggurat(s->rng, 1.0);
		s->draws++;
		const double value = s->magnitude * s->z[j];
		s->held_lo = n;
		s->held_hi = n + whole;
		s->held_value = value;
		s->held_j = j;
		held[0] = s->held_lo;
		held[1] = s->held_hi;
		return value;
	}
	double value = bsim_schedule_at_step(s, n, h);
	/* Held now: either the hold read above or the one just set, whose
	 * value is the one returned. */
	int holds = n >= s->held_lo && n < s->held_hi && h == s->held_h;
	held[0] = holds ? s->held_lo : 0;
	held[1] = holds ? s->held_hi : 0;
	return value;
}

double bsim_schedule_value(bsim_schedule *s, long j)
{
	/* A value that cannot be had is no value: 0, and the failure kept for
	 * bsim_schedule_status, which fails the trial. */
	if (j < 0 || j >= SCHEDULE_MAX) {
		s->failed = s->failed ? s->failed : (j < 0 ? -1 : j);
		return 0.0;
	}
	if (j >= s->n_drawn) {
		if (j >= s->cap) {
			long cap = s->cap ? s->cap : 256;
			while (cap <= j)
				cap *= 2;
			double *z = realloc(s->z, (size_t)cap * sizeof *z);
			if (!z) {
				s->failed = s->failed ? s->failed : j;
				s->oom = 1;
				return 0.0;
			}
			s->z = z;
			s->cap = cap;
		}
		while (s->n_drawn <= j) {
			s->z[s->n_drawn++] = gsl_ran_gaussian_ziggurat(s->rng, 1.0);
			s->draws++;
		}
	}
	return s->magnitude * s->z[j];
}

void bsim_schedule_values(bsim_schedule *s, long j, int n, double *out)
{
	for (int k = 0; k < n; k++)
		out[k] = schedule_value_at(s, j + k);
}

int bsim_schedule_status(const bsim_schedule *s, bsim_error *err)
{
	if (!s->failed)
		return BSIM_OK;
	if (s->oom)
		return bsim_error_set(err, BSIM_EFAIL,
		                      "out of memory for the random force's value %ld", s->failed);
	return bsim_error_set(
	        err, BSIM_EFAIL,
	        "random force: value %ld is beyond any schedule (at most 2^40 values)", s->failed);
}

void bsim_schedule_used(bsim_schedule *s, long n)
{
	/* One draw a value, in order: the draws of the values from n on are
	 * those made ahead. Those already added to total_draws stay counted. */
	if (n >= 0 && (unsigned long)n < s->draws)
		s->draws = (unsigned long)n > s->counted ? (unsigned long)n : s->counted;
}

unsigned long bsim_schedule_draws(const bsim_schedule *s)
{
	return s->draws;
}

unsigned long bsim_schedule_total_draws(void)
{
	return __atomic_load_n(&total_draws, __ATOMIC_RELAXED);
}
