/* The whole API of libbeamsim in one include (docs/architecture.md "The
 * API and the ABI"): every public header of include/beamsim/. A program may
 * include the few it needs instead; what libbeamsim.so exports is exactly
 * what these declare (BSIM_API, beamsim/base.h). */
#ifndef BSIM_BEAMSIM_H
#define BSIM_BEAMSIM_H

#include "beamsim/accuracy.h"
#include "beamsim/backend.h"
#include "beamsim/backend_registry.h"
#include "beamsim/base.h"
#include "beamsim/body_shape.h"
#include "beamsim/compare.h"
#include "beamsim/compare_dir.h"
#include "beamsim/contact_flag.h"
#include "beamsim/effects.h"
#include "beamsim/error.h"
#include "beamsim/essay_compare.h"
#include "beamsim/experiment.h"
#include "beamsim/key_names.h"
#include "beamsim/figures.h"
#include "beamsim/landscape.h"
#include "beamsim/landscape_barriers.h"
#include "beamsim/lattice.h"
#include "beamsim/lattice_outcome.h"
#include "beamsim/limits.h"
#include "beamsim/markov.h"
#include "beamsim/options.h"
#include "beamsim/output.h"
#include "beamsim/override.h"
#include "beamsim/progress.h"
#include "beamsim/replay.h"
#include "beamsim/regress.h"
#include "beamsim/report.h"
#include "beamsim/run_output.h"
#include "beamsim/run_record.h"
#include "beamsim/scene.h"
#include "beamsim/schedule.h"
#include "beamsim/state.h"
#include "beamsim/stats.h"
#include "beamsim/sweep.h"
#include "beamsim/sweep_dir.h"
#include "beamsim/table.h"
#include "beamsim/trajectory.h"
#include "beamsim/trial.h"
#include "beamsim/version.h"
#include "beamsim/video.h"

#endif
