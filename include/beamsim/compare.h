/* Comparing sweeps trial by trial: two or more backends (or settings of
 * one) run with the same schedules (beamsim compare) or a stored sweep and
 * its rerun (beamsim regress). Trial t of group g in one is the pair of
 * trial t of group g in another, so every test here is a paired one. */
#ifndef BSIM_COMPARE_H
#define BSIM_COMPARE_H

#include <stdint.h>

#include "beamsim/base.h"
#include "beamsim/error.h"
#include "beamsim/stats.h"
#include "beamsim/sweep.h"
#include "beamsim/lattice_outcome.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The per-trial events compared: each is a yes/no of one trial. */
typedef enum {
	BSIM_EVENT_TRAVERSED = 0,
	BSIM_EVENT_LEFT,  /* traversed over the left beam */
	BSIM_EVENT_RIGHT, /* traversed over the right beam */
	BSIM_EVENT_SIDE_EXIT,
	BSIM_EVENT_STUCK,
	BSIM_EVENT_UNSTABLE, /* the backend failed (non-finite, or energy created) */
	BSIM_N_EVENTS
} bsim_event;

BSIM_API const char *bsim_compare_event_name(bsim_event ev);
/* 1 if trial r shows event ev. */
BSIM_API int bsim_compare_event_of(const bsim_trial_result *r, bsim_event ev);

/* When a group disagrees: some event's McNemar p-value, Holm-adjusted over
 * every (group, event) test of the comparison, is below alpha AND that
 * event's probabilities differ by at least margin. The margin keeps a
 * statistically clear but practically negligible difference (likely with
 * many trials) from failing a guard; set it to 0 for significance alone.
 * exact: any trial not identical in every trials.csv field makes its
 * group disagree (regress --exact: identical code and inputs must give
 * identical trials).
 *
 * A group without random draws (bsim_group_result.deterministic on either
 * side) is one trial, not a sample: it is compared as one pair, same or
 * different, with no interval or p-value, and stays out of the Holm
 * family. A deterministic pair that differs in outcome or type disagrees.
 *
 * The Holm family holds, for each random group, the events whose
 * hypotheses are not implied by the others' (bsim_compare_family).
 *
 * An event is "informative" unless both probabilities lie within the margin
 * of 0 or both within the margin of 1: at the floor or the ceiling two
 * backends agree within the margin whatever their physics. A group that
 * does not disagree is "equivalent" when at least one event is informative
 * and, for every informative event, Tango's two one-sided tests show the
 * difference within +-margin at level alpha; "uninformative" when no event
 * is informative; otherwise the comparison could not tell ("inconclusive":
 * no difference detected, none excluded either). Each group's equivalence
 * is tested at alpha without correction: the claim that every group is
 * equivalent is an intersection-union test, valid at alpha as it is. */
typedef struct bsim_compare_rule {
	double alpha;  /* family-wise error rate, (0, 1) */
	double margin; /* |p_A - p_B|, [0, 1] */
	int exact;
} bsim_compare_rule;

/* alpha 0.05, margin 0.05, not exact. */
BSIM_API bsim_compare_rule bsim_compare_rule_default(void);

typedef struct bsim_event_test {
	bsim_pairs pairs;        /* a: both, b: only A, c: only B, d: neither */
	double p_a, p_b;         /* event probabilities */
	double ci_a[2], ci_b[2]; /* Wilson 95% */
	double diff, diff_ci[2]; /* p_a - p_b, Tango's paired score 95% */
	double p_value, p_holm;  /* exact McNemar, and Holm-adjusted */
	double p_equivalence;    /* Tango's two one-sided tests against +-margin */
	double mde80;            /* the |p_a - p_b| the exact McNemar test at the
	                          * family's level (alpha / n_tests) detects with
	                          * power 0.8 at this event's discordance
	                          * (bsim_stats_mcnemar_mde) */
	double min_significant;  /* the smallest |b - c| / n that is significant at
	                          * that level with this event's number of
	                          * discordant pairs (at least the fewest that can
	                          * be), i.e. with them split as unevenly as a
	                          * significant result needs: a bound, not a power */
	int in_family;           /* tested in the rule (bsim_compare_family) */
	int informative;         /* not both p within margin of 0, nor both of 1 */
	int beyond;              /* in the family, p_holm < alpha, |diff| >= margin */
	int equivalent;          /* p_equivalence < alpha */
} bsim_event_test;

/* The events of a random group's Holm family, by structure and by the
 * outcome cells (traversed left, right or none, side exit, stuck,
 * unstable) that occur in the group on either side. Each event is the set
 * of its cells, and since every trial is in exactly one cell the cells'
 * indicators sum to 1. Events are taken in the order unstable, left,
 * right, side_exit, traversed, stuck, each only if its indicator over the
 * occurring cells is not a linear combination of those taken and the
 * constant 1: then its null hypothesis (p_A = p_B) is implied by theirs.
 * So an event that never occurs on either side (structurally zero here:
 * its McNemar p is 1 whatever happens, and it would only raise Holm's
 * multiplier) is out; so is the outcome that is the complement of the
 * others that occur (stuck, or side_exit when nothing is stuck), and
 * traversed unless some traversal is of type none (else it is left +
 * right: the components are kept, as they tell which beam the body went
 * over and neither is preferred to the other). The occurring cells do not change when the two sides
 * of any pair are swapped, so under the null hypothesis of exchangeable pairs each kept test stays
 * exact given the choice. cells: the occurring cells, bit c for cell c in the order traversed left,
 * right, none, side_exit, stuck, unstable; returns the family's events as bits 1 << bsim_event. */
BSIM_API unsigned bsim_compare_family(unsigned cells);

/* The verdicts, from "nothing to see" to "disagree". Deterministic groups
 * are same or DIFFERENT; the others one of the five between. */
typedef enum {
	BSIM_VERDICT_SAME = 0,          /* deterministic: the one pair alike */
	BSIM_VERDICT_EQUIVALENT = 1,    /* every informative event shown within +-margin */
	BSIM_VERDICT_UNINFORMATIVE = 2, /* every event at the floor or the ceiling */
	BSIM_VERDICT_INCONCLUSIVE = 3,  /* no difference detected, none excluded */
	BSIM_VERDICT_SMALL = 4,         /* significant, but within the margin */
	BSIM_VERDICT_DISAGREE = 5,      /* beyond the rule */
	BSIM_VERDICT_DIFFERENT = 6,     /* deterministic: the one pair differs */
	BSIM_N_VERDICTS
} bsim_verdict;

BSIM_API const char *bsim_compare_verdict_name(bsim_verdict v);

/* Lattices: where the paired trials ended (bsim_lattice_location_of). The test of
 * "both sides have the same final-location distribution" is a paired
 * permutation test: under that hypothesis the two locations of a pair are
 * exchangeable, so each of the d discordant pairs is swapped or not with
 * probability 1/2, and the statistic
 *   T = sum over locations |count_A - count_B|   (= 2 n x total variation)
 * is compared with its permutation distribution. p = P(T* >= T): all 2^d
 * swaps are enumerated when d <= 20 (exact), else 20,000 random ones
 * (Monte Carlo, fixed seed, p = (1 + #{T* >= T}) / 20,001). */
typedef struct bsim_location_test {
	int discordant; /* pairs ending in different locations */
	double tv;      /* total variation distance of the two distributions */
	double p_value, p_holm;
	int exact;      /* 1: enumerated; 0: Monte Carlo */
	long resamples; /* swaps evaluated */
	int beyond;     /* p_holm < alpha and tv >= margin */
} bsim_location_test;

#define BSIM_LOCATION_EXACT_MAX 20
#define BSIM_LOCATION_RESAMPLES 20000

/* The paired permutation test on n pairs of final locations. */
BSIM_API void bsim_compare_location_test(const bsim_trial_result *a, const bsim_trial_result *b,
                                         int n, uint64_t seed, bsim_location_test *out);

typedef struct bsim_compare_group {
	int deterministic; /* one pair: ev has the 0/1 events, no statistics */
	int pairs;         /* pairs compared: trials, or 1 if deterministic */
	bsim_event_test ev[BSIM_N_EVENTS];
	bsim_location_test loc; /* lattices only */
	int discordant;         /* pairs with a different outcome or type */
	unsigned family;        /* the events in the Holm family, 1 << bsim_event */
	int changed;     /* trials (copies included) not identical in some trials.csv field */
	int separated;   /* pairs whose trajectories separated */
	double t_sep[3]; /* 10%, 50%, 90% quantiles of the separation time
	                  * over separated pairs, s; -1 if none */
	bsim_verdict verdict;
} bsim_compare_group;

typedef struct bsim_comparison {
	int n_groups, trials;
	int lattice; /* 1: the final-location test is in the rule (and the Holm family) */
	bsim_compare_rule rule;
	bsim_compare_group *groups;
	int n_tests;    /* the Holm family's size: each random group's family events
	                 * (bsim_compare_family), and its final-location test on a
	                 * lattice */
	int n_disagree; /* groups DISAGREE or DIFFERENT */
	int count[BSIM_N_VERDICTS];
	int separated; /* pairs that separated, over all groups */
	int pairs;     /* pairs compared, over all groups */
	double t_sep[3];
} bsim_comparison;

/* Compares a and b (same groups and trials). t_separate may be NULL (no
 * trajectories, e.g. regress). BSIM_EINPUT if the shapes differ. */
BSIM_API int bsim_compare_analyse(const bsim_sweep_result *a, const bsim_sweep_result *b,
                                  const double *t_separate, const bsim_compare_rule *rule,
                                  bsim_comparison *out, bsim_error *err);
BSIM_API void bsim_compare_free(bsim_comparison *c);

/* ---- more than two sides ----------------------------------------------------
 *
 * A comparison of n sides (2 to BSIM_COMPARE_SIDES_MAX) compares every pair
 * of sides as above, with one Holm family: every pair's tests together, so
 * that the chance that any agreeing pair of any group is called
 * disagreeing stays below alpha however many sides there are. Each pair's
 * n_tests is that family's size, and its mde80 and min_significant are at
 * the family's level. A group's verdict is its least agreeing pair's (the
 * largest in bsim_verdict's order); it disagrees when any pair does.
 *
 * The odd one out of a group says which side a disagreement is due to: the
 * side s such that every pair of s with another side disagrees (DISAGREE
 * or DIFFERENT) and no pair of the other sides does. With three sides or
 * more at most one side can be it; with two, both sides would be, so two
 * sides never have one. bsim_compare_odd_one_out returns it, or
 * BSIM_ODD_NONE when no pair disagrees, or BSIM_ODD_NO_SINGLE when some
 * pair disagrees but no single side is the odd one out (two sides
 * disagreeing with the rest, a pair of the others disagreeing, or a side
 * that disagrees with some but not all of the others). */

#define BSIM_COMPARE_SIDES_MAX BSIM_SWEEP_SIDES_MAX
#define BSIM_ODD_NONE          (-1)
#define BSIM_ODD_NO_SINGLE     (-2)

/* The odd one out of n_sides sides from differ[k], nonzero when pair k (in
 * bsim_sweep_pair's order) disagrees. */
BSIM_API int bsim_compare_odd_one_out(int n_sides, const int *differ);

typedef struct bsim_compare_sides {
	int n_sides, n_pairs;
	int n_groups, trials;
	int pair[BSIM_SWEEP_PAIRS_MAX][2];           /* pair k's sides (bsim_sweep_pair) */
	bsim_comparison pairs[BSIM_SWEEP_PAIRS_MAX]; /* pair k: side pair[k][0] as A,
	                                              * pair[k][1] as B */
	int n_tests;                /* the one Holm family's size, over every pair */
	bsim_verdict *verdict;      /* per group: its least agreeing pair's */
	int *odd;                   /* per group: the odd one out, a side, or BSIM_ODD_* */
	int n_disagree;             /* groups in which some pair disagrees */
	int count[BSIM_N_VERDICTS]; /* groups by verdict */
} bsim_compare_sides;

/* Compares n_sides sweeps (same groups and trials) pair by pair.
 * t_separate may be NULL, else the pairs' separation times as
 * bsim_sweep_run_sides gives them. BSIM_EINPUT if the shapes differ or
 * n_sides is out of range. bsim_compare_analyse is n_sides = 2, its
 * result the one pair's. */
BSIM_API int bsim_compare_analyse_sides(const bsim_sweep_result *side, int n_sides,
                                        const double *t_separate, const bsim_compare_rule *rule,
                                        bsim_compare_sides *out, bsim_error *err);
BSIM_API void bsim_compare_sides_free(bsim_compare_sides *c);

/* 1 if trials differ in outcome or traversal type. */
BSIM_API int bsim_compare_discordant(const bsim_trial_result *a, const bsim_trial_result *b);
/* The fields of trials.csv that a file may lack (one written before them),
 * compared only where both sides have them: a bit set. */
enum { BSIM_COMPARE_LEDGER = 1, BSIM_COMPARE_TURN = 2 };

/* The fields both results know (BSIM_COMPARE_LEDGER if both have_ledger,
 * BSIM_COMPARE_TURN if both has_turn). */
BSIM_API int bsim_compare_known(const bsim_sweep_result *a, const bsim_sweep_result *b);

/* 1 if trials are identical in every field trials.csv records (the
 * ledger's and the turn's only where known has their bit). */
BSIM_API int bsim_compare_identical(const bsim_trial_result *a, const bsim_trial_result *b,
                                    int known);

#ifdef __cplusplus
}
#endif
#endif
