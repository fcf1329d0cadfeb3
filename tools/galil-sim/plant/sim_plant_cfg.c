/*
 * sim_plant_cfg.c - the YAML plant file (config/plant.yaml) for sim_plant.
 *
 * base_yaml loads the whole document (base_file reads the file); a table
 * per mapping says which keys exist and where their values go. Every key is
 * optional (the defaults stay), unknown and duplicate keys are rejected, and
 * nothing is applied unless the whole file is valid. Positions from libyaml are
 * 0-based; the messages say LINE:COLUMN 1-based.
 */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "base_file.h"
#include "base_yaml.h"
#include "gl_err.h"
#include "sim_plant.h"

#define PLANT_FILE_MAX (1 << 20) /* bytes */

enum ftype {
	F_DOUBLE,
	F_INT,
	F_BOOL,
	F_SEED,
	F_KIND,
	F_NOISE,
	F_MAP,
	F_AXES,
	F_JOYIN
};

struct field {
	const char *key;
	enum ftype type;
	size_t off;		 /* into the struct being filled */
	const struct field *sub; /* F_MAP: the nested table */
};

struct ycx {
	yaml_document_t *doc;
	const char *name;
	char *err;
	size_t errlen;
};

#define POT(m) offsetof(struct sim_plant_pot_cfg, m)
#define AX(m)  offsetof(struct sim_plant_axis_cfg, m)
#define CFG(m) offsetof(struct sim_plant_cfg, m)

static const struct field pot_fields[] = {
    {"input", F_INT, POT(input), NULL},
    {"rev_v", F_DOUBLE, POT(rev_v), NULL},
    {"fwd_v", F_DOUBLE, POT(fwd_v), NULL},
    {"nonlinear_v", F_DOUBLE, POT(nonlinear_v), NULL},
    {"noise_v", F_DOUBLE, POT(noise_v), NULL},
    {"noise", F_NOISE, POT(noise), NULL},
    {"open_v", F_DOUBLE, POT(open_v), NULL},
    {NULL, F_INT, 0, NULL},
};

static const struct field axis_fields[] = {
    {"kind", F_KIND, AX(rotary), NULL},
    {"rev_limit", F_DOUBLE, AX(rev_limit), NULL},
    {"fwd_limit", F_DOUBLE, AX(fwd_limit), NULL},
    {"end_stop", F_DOUBLE, AX(end_stop), NULL},
    {"start", F_DOUBLE, AX(start), NULL},
    {"max_speed", F_DOUBLE, AX(max_speed), NULL},
    {"lag_ms", F_DOUBLE, AX(lag_ms), NULL},
    {"home", F_DOUBLE, AX(home), NULL},
    {"encoder_reversed", F_BOOL, AX(encoder_reversed), NULL},
    {"limits_swapped", F_BOOL, AX(limits_swapped), NULL},
    {"pot", F_MAP, AX(pot), pot_fields},
    {NULL, F_INT, 0, NULL},
};

static const struct field joy_fields[] = {
    {"closed_level", F_INT, CFG(joy_closed_level), NULL},
    {"inputs", F_JOYIN, CFG(joy_input), NULL},
    {NULL, F_INT, 0, NULL},
};

static const struct field root_fields[] = {
    {"seed", F_SEED, CFG(seed), NULL},
    {"axes", F_AXES, CFG(axis), NULL},
    {"joystick", F_MAP, 0, joy_fields},
    {"amp_undervoltage", F_BOOL, CFG(amp_undervoltage), NULL},
    {"power_output", F_INT, CFG(power_output), NULL},
    {"relay_wired", F_BOOL, CFG(relay_wired), NULL},
    {NULL, F_INT, 0, NULL},
};

static const char *const joy_keys[6] = {"A_fwd", "A_rev", "B_fwd",
					"B_rev", "C_fwd", "C_rev"};

static int walk_map(struct ycx *cx, yaml_node_t *map, const struct field *table,
		    void *base, const char *where);

static int yerr(struct ycx *cx, const yaml_node_t *n, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* "NAME:LINE:COLUMN: message" at node @n (1:1 without a node). */
static int yerr(struct ycx *cx, const yaml_node_t *n, const char *fmt, ...)
{
	static const yaml_mark_t top = {0, 0, 0};
	va_list ap;

	va_start(ap, fmt);
	base_yaml_vformat(cx->err, cx->errlen, cx->name,
			  n ? &n->start_mark : &top, fmt, ap);
	va_end(ap);
	return GL_ERR_CONFIG;
}

static int get_double(struct ycx *cx, yaml_node_t *n, const char *key,
		      double *out)
{
	const char *s = base_yaml_scalar(n);

	if (!s || !*s)
		return yerr(cx, n, "'%s' must be a number", key);
	if (base_yaml_double(n, out) < 0)
		return yerr(cx, n, "'%s' must be a number, not '%s'", key, s);
	return 0;
}

static int get_long(struct ycx *cx, yaml_node_t *n, const char *key, long *out)
{
	const char *s = base_yaml_scalar(n);
	long v;

	if (!s || !*s)
		return yerr(cx, n, "'%s' must be an integer", key);
	if (base_yaml_long(n, &v) < 0 || v < -2147483647L || v > 2147483647L)
		return yerr(cx, n, "'%s' must be an integer, not '%s'", key, s);
	*out = v;
	return 0;
}

static int get_word(struct ycx *cx, yaml_node_t *n, const char *key,
		    const char *a, const char *b, int *out)
{
	const char *s = base_yaml_scalar(n);

	if (s && !strcmp(s, a))
		*out = 0;
	else if (s && !strcmp(s, b))
		*out = 1;
	else
		return yerr(cx, n, "'%s' must be '%s' or '%s'", key, a, b);
	return 0;
}

/* A mapping whose keys are all scalars and all different. */
static int check_map(struct ycx *cx, yaml_node_t *map, const char *where)
{
	yaml_node_pair_t *p;
	yaml_node_t *k;
	int rc;

	if (!map || map->type != YAML_MAPPING_NODE)
		return yerr(cx, map, "%s must be a mapping", where);
	for (p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top;
	     p++) {
		rc = base_yaml_key(cx->doc, map, p, &k);
		if (rc == -EEXIST)
			return yerr(cx, k, "duplicate key '%s' in %s",
				    base_yaml_scalar(k), where);
		if (rc < 0)
			return yerr(cx, k, "keys of %s must be plain words",
				    where);
	}
	return 0;
}

static int get_pair(struct ycx *cx, yaml_node_t *n, const char *key, int *out)
{
	yaml_node_item_t *it;
	long v;
	int i = 0;

	if (!n || n->type != YAML_SEQUENCE_NODE ||
	    n->data.sequence.items.top - n->data.sequence.items.start != 2)
		return yerr(cx, n,
			    "'%s' must be a list of two input numbers "
			    "[a, b]",
			    key);
	for (it = n->data.sequence.items.start; it < n->data.sequence.items.top;
	     it++, i++) {
		yaml_node_t *e = yaml_document_get_node(cx->doc, *it);

		if (get_long(cx, e, key, &v) < 0)
			return GL_ERR_CONFIG;
		if (v < 1 || v > CTRL_INPUTS)
			return yerr(cx, e, "'%s' input %ld outside 1..%d", key,
				    v, CTRL_INPUTS);
		out[i] = (int)v;
	}
	return 0;
}

static int walk_joy_inputs(struct ycx *cx, yaml_node_t *map, int *joy)
{
	yaml_node_pair_t *p;

	if (check_map(cx, map, "joystick.inputs") < 0)
		return GL_ERR_CONFIG;
	for (p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top;
	     p++) {
		yaml_node_t *k = yaml_document_get_node(cx->doc, p->key);
		yaml_node_t *v = yaml_document_get_node(cx->doc, p->value);
		int cmd = -1;

		for (int i = 0; i < 6; i++) {
			if (!strcmp(base_yaml_scalar(k), joy_keys[i]))
				cmd = i;
		}
		if (cmd < 0)
			return yerr(cx, k,
				    "unknown key '%s' in joystick.inputs"
				    " (A_fwd A_rev B_fwd B_rev C_fwd C_rev)",
				    base_yaml_scalar(k));
		if (get_pair(cx, v, base_yaml_scalar(k), &joy[2 * cmd]) < 0)
			return GL_ERR_CONFIG;
	}
	return 0;
}

static int walk_axes(struct ycx *cx, yaml_node_t *map,
		     struct sim_plant_axis_cfg *axes)
{
	yaml_node_pair_t *p;
	char where[16];

	if (check_map(cx, map, "axes") < 0)
		return GL_ERR_CONFIG;
	for (p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top;
	     p++) {
		yaml_node_t *k = yaml_document_get_node(cx->doc, p->key);
		yaml_node_t *v = yaml_document_get_node(cx->doc, p->value);
		const char *s = base_yaml_scalar(k);

		if (strlen(s) != 1 || s[0] < 'A' || s[0] > 'C')
			return yerr(cx, k, "unknown axis '%s' (A, B or C)", s);
		snprintf(where, sizeof(where), "axes.%c", s[0]);
		if (walk_map(cx, v, axis_fields, &axes[s[0] - 'A'], where) < 0)
			return GL_ERR_CONFIG;
	}
	return 0;
}

static int set_field(struct ycx *cx, const struct field *f, yaml_node_t *v,
		     void *base, const char *where)
{
	void *dst = (char *)base + f->off;
	char sub[64];
	long l;

	switch (f->type) {
	case F_DOUBLE: return get_double(cx, v, f->key, (double *)dst);
	case F_INT:
		if (get_long(cx, v, f->key, &l) < 0)
			return GL_ERR_CONFIG;
		*(int *)dst = (int)l;
		return 0;
	case F_SEED:
		if (get_long(cx, v, f->key, &l) < 0)
			return GL_ERR_CONFIG;
		if (l < 0)
			return yerr(cx, v, "'%s' must be >= 0", f->key);
		*(unsigned long *)dst = (unsigned long)l;
		return 0;
	case F_BOOL:
		return get_word(cx, v, f->key, "false", "true", (int *)dst);
	case F_KIND:
		/* rotary is 1: "linear" -> 0, "rotary" -> 1 */
		return get_word(cx, v, f->key, "linear", "rotary", (int *)dst);
	case F_NOISE:
		return get_word(cx, v, f->key, "gaussian", "uniform",
				(int *)dst);
	case F_MAP:
		snprintf(sub, sizeof(sub), "%s%s%s", where, *where ? "." : "",
			 f->key);
		return walk_map(cx, v, f->sub, dst, sub);
	case F_AXES: return walk_axes(cx, v, (struct sim_plant_axis_cfg *)dst);
	case F_JOYIN: return walk_joy_inputs(cx, v, (int *)dst);
	}
	return yerr(cx, v, "internal error");
}

static int walk_map(struct ycx *cx, yaml_node_t *map, const struct field *table,
		    void *base, const char *where)
{
	yaml_node_pair_t *p;

	if (check_map(cx, map, *where ? where : "the plant file") < 0)
		return GL_ERR_CONFIG;
	for (p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top;
	     p++) {
		yaml_node_t *k = yaml_document_get_node(cx->doc, p->key);
		yaml_node_t *v = yaml_document_get_node(cx->doc, p->value);
		const struct field *f = table;

		while (f->key && strcmp(f->key, base_yaml_scalar(k)))
			f++;
		if (!f->key)
			return yerr(cx, k, "unknown key '%s'%s%s",
				    base_yaml_scalar(k), *where ? " in " : "",
				    where);
		if (set_field(cx, f, v, base, where) < 0)
			return GL_ERR_CONFIG;
	}
	return 0;
}

/* Where a failed whole-config check points: the value of the top-level
 * key its message starts with ("axis B: ..." -> axes, "joystick input ...",
 * "power_output 9 ..."), else the whole document. */
static yaml_node_t *section_node(struct ycx *cx, yaml_node_t *root,
				 const char *msg)
{
	char sect[32];
	yaml_node_pair_t *p;

	if (!strncmp(msg, "axis ", 5))
		snprintf(sect, sizeof(sect), "axes");
	else
		snprintf(sect, sizeof(sect), "%.*s", (int)strcspn(msg, " "),
			 msg);
	for (p = root->data.mapping.pairs.start;
	     p < root->data.mapping.pairs.top; p++) {
		if (!strcmp(base_yaml_scalar(
				yaml_document_get_node(cx->doc, p->key)),
			    sect))
			return yaml_document_get_node(cx->doc, p->value);
	}
	return root;
}

static int parse_doc(struct ycx *cx, struct sim_plant_cfg *cfg)
{
	yaml_node_t *root = yaml_document_get_root_node(cx->doc);
	struct sim_plant_cfg tmp = *cfg;
	char msg[200];

	if (!root)
		return yerr(cx, NULL, "empty plant file");
	if (walk_map(cx, root, root_fields, &tmp, "") < 0)
		return GL_ERR_CONFIG;
	if (sim_plant_cfg_check(&tmp, msg, sizeof(msg)) < 0)
		return yerr(cx, section_node(cx, root, msg), "%s", msg);
	*cfg = tmp;
	return 0;
}

int sim_plant_cfg_parse(struct sim_plant_cfg *cfg, const char *buf, size_t len,
			const char *name, char *err, size_t errlen)
{
	yaml_document_t doc;
	struct base_yaml_error e;
	struct ycx cx = {&doc, name, err, errlen};
	int rc = base_yaml_load(buf, len, 0, &doc, &e);

	if (rc == -ENOMEM && !e.problem)
		return yerr(&cx, NULL, "out of memory");
	if (rc < 0) {
		/* a reader error (bad encoding) has no line: 1:1, as before */
		snprintf(err, errlen, "%s:%lu:%lu: %s", name,
			 e.type == YAML_READER_ERROR
			     ? 1UL
			     : (unsigned long)e.mark.line + 1,
			 e.type == YAML_READER_ERROR
			     ? 1UL
			     : (unsigned long)e.mark.column + 1,
			 e.problem ? e.problem : "invalid YAML");
		return GL_ERR_CONFIG;
	}
	rc = parse_doc(&cx, cfg);
	yaml_document_delete(&doc);
	return rc;
}

int sim_plant_cfg_load(struct sim_plant_cfg *cfg, const char *path, char *err,
		       size_t errlen)
{
	char *buf;
	size_t n;
	/* a file of PLANT_FILE_MAX bytes or more is refused */
	int rc = base_file_read(path, PLANT_FILE_MAX - 1, &buf, &n);

	switch (rc) {
	case 0: break;
	case -EFBIG:
		snprintf(err, errlen, "%s:0:0: plant file larger than 1 MiB",
			 path);
		return GL_ERR_CONFIG;
	case -ENOMEM:
		snprintf(err, errlen, "%s:0:0: out of memory", path);
		return GL_ERR_CONFIG;
	case -EISDIR:
	case -EINVAL:
	case -EIO:
		snprintf(err, errlen, "%s:0:0: cannot read plant file", path);
		return GL_ERR_CONFIG;
	default:
		snprintf(err, errlen, "%s:0:0: cannot open plant file: %s",
			 path, strerror(-rc));
		return GL_ERR_CONFIG;
	}
	rc = sim_plant_cfg_parse(cfg, buf, n, path, err, errlen);
	free(buf);
	return rc;
}
