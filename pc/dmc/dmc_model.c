/*
 * dmc_model.c - controller family limits. See dmc_model.h.
 */
#include "dmc_model.h"

#include <stddef.h>
#include <strings.h>

/*
 * Labels with '_': the command reference's '#' page allows letters and
 * digits only, for every family; its own JP example and production
 * programs run on DMC-40x0 hardware use '_' inside labels. The 40x0
 * follows the hardware evidence; the other families, with no such
 * evidence, keep the reference's rule (docs/galil-sim.md).
 */
static const struct dmc_model models[] = {
    {"40x0", "DMC-40x0", DMC_LINE_MAX, DMC_40X0_LINES, DMC_40X0_LABELS,
     DMC_40X0_VARS, DMC_40X0_THREADS, 1, 1},
    {"41x3", "DMC-41x3", DMC_LINE_MAX, 2000, 254, 254, 8, 0, 0},
    {"21x3", "DMC-21x3", DMC_LINE_MAX, 1000, 254, 254, 8, 0, 0},
    {"30010", "DMC-30010", DMC_LINE_MAX, 2000, 254, 254, 6, 0, 0},
};

const struct dmc_model *dmc_model_default(void)
{
	return &models[0];
}

const struct dmc_model *dmc_model_find(const char *name)
{
	static const char *const alias[][2] = {
	    {"4020", "40x0"}, {"4030", "40x0"},	  {"4040", "40x0"},
	    {"4050", "40x0"}, {"4060", "40x0"},	  {"4070", "40x0"},
	    {"4080", "40x0"}, {"4103", "41x3"},	  {"4123", "41x3"},
	    {"4133", "41x3"}, {"4143", "41x3"},	  {"4163", "41x3"},
	    {"4183", "41x3"}, {"2103", "21x3"},	  {"2123", "21x3"},
	    {"2133", "21x3"}, {"2143", "21x3"},	  {"2163", "21x3"},
	    {"2183", "21x3"}, {"31010", "30010"},
	};
	size_t i;

	if (!strncasecmp(name, "DMC", 3))
		name += name[3] == '-' ? 4 : 3;
	for (i = 0; i < sizeof(alias) / sizeof(alias[0]); i++)
		if (!strcasecmp(name, alias[i][0]))
			name = alias[i][1];
	for (i = 0; i < sizeof(models) / sizeof(models[0]); i++)
		if (!strcasecmp(name, models[i].name))
			return &models[i];
	return NULL;
}
