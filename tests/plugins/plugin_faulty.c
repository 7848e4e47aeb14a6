/* Plug-ins that beamsim must refuse, one per FAULT (test_plugin): each
 * exports a table that a loader's check finds wrong. */
#include "beamsim/backend_plugin.h"

static int create(const bsim_scene *scene, const bsim_options *opts, bsim_world **out,
                  bsim_error *err)
{
	(void)scene;
	(void)opts;
	*out = NULL;
	return bsim_error_set(err, BSIM_EFAIL, "faulty: never creates a world");
}

static void destroy(bsim_world *w)
{
	(void)w;
}

static void get_state(const bsim_world *w, bsim_state *out)
{
	(void)w;
	(void)out;
}

static int set_state(bsim_world *w, const bsim_state *s, bsim_error *err)
{
	(void)w;
	(void)s;
	(void)err;
	return BSIM_OK;
}

#if FAULT != 2
static int advance(bsim_world *w, const bsim_wrench *schedule, double h, int n, bsim_state *out,
                   int *made, bsim_error *err)
{
	(void)w;
	(void)schedule;
	(void)h;
	(void)n;
	(void)out;
	*made = 0;
	return bsim_error_set(err, BSIM_EFAIL, "faulty: never advances");
}
#endif

static const bsim_backend faulty = {
#if FAULT == 1 /* a built-in backend's name */
        .name = "thesis",
#elif FAULT == 3 /* a name that is not one */
        .name = "bad name",
#else
        .name = "faulty",
#endif
        .create = create,
        .destroy = destroy,
#if FAULT != 2 /* a required field left empty */
        .advance = advance,
#endif
        .get_state = get_state,
        .set_state = set_state,
};

#if FAULT == 4 /* built against another interface */
BSIM_PLUGIN_EXPORT extern const bsim_backend_plugin bsim_plugin;
const bsim_backend_plugin bsim_plugin = {BSIM_BACKEND_ABI + 1, sizeof(bsim_backend),
                                         sizeof(bsim_state), &faulty};
#else
BSIM_BACKEND_PLUGIN(faulty);
#endif
