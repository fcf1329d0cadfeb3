/*
 * re_config.c - the supervisor's YAML configuration (libyaml document API):
 * the parse of a whole file, validation after command-line overrides, and
 * what is derived from a configuration (the relay's settings, its hash, a
 * summary).
 *
 * The file is loaded into a libyaml document, then walked with the tables
 * of re_config_schema.c, which give every key its type, its place in
 * struct re_config and its range. Parsing stores values and remembers
 * where each one was written (yaml marks by field address); validation
 * (re_config_check.c) then checks ranges and cross-field rules on the
 * struct, so re_config_validate() (after command line overrides) and
 * re_config_parse() apply exactly the same rules, the latter with the
 * position of the value concerned (for a cross-field rule, the later of
 * the values involved). Everything goes into a temporary struct copied
 * out only on success.
 */
#include "re_config_int.h"

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base_file.h"
#include "base_paths.h"
#include "base_yaml.h"
#include "gl_err.h"
#include "gl_hash.h"
#include "gl_link.h"
#include "re_rt.h"

/* ---- parse ---- */

/* Say why base_yaml_load() failed, at the place libyaml gives. */
/* Where a quoted value of line @ln (@p .. @end) opens without closing on
 * that line: its 0-based column, or -1. A quote opens a value after ": ",
 * "- ", "[" or "," (a quote inside a plain value, as in don't, opens
 * nothing); '' and \" do not close. */
static long open_quote_col(const char *p, const char *end)
{
	const char *b = p;

	for (const char *q = p; q < end; q++) {
		const char *v = q;
		char quote;

		if (*q == '#' && (q == b || q[-1] == ' ' || q[-1] == '\t'))
			return -1; /* a comment */
		if (*q != ':' && *q != '-' && *q != '[' && *q != ',')
			continue;
		v = q + 1;
		if (*q != '[' && *q != ',' && (v >= end || *v != ' '))
			continue;
		while (v < end && *v == ' ')
			v++;
		if (v >= end || (*v != '"' && *v != '\''))
			continue;
		quote = *v;
		for (q = v + 1; q < end; q++) {
			if (quote == '"' && *q == '\\' && q + 1 < end)
				q++;
			else if (quote == '\'' && *q == '\'' && q + 1 < end &&
				 q[1] == '\'')
				q++;
			else if (*q == quote)
				break;
		}
		if (q >= end)
			return v - b;
	}
	return -1;
}

/* The first line up to @last (0-based) with a quote that is not closed on
 * it: a double-quoted YAML value may span lines, so libyaml reports the
 * error where the quote finally closes, often many lines later. */
static int unclosed_quote(const char *buf, size_t len, size_t last,
			  yaml_mark_t *at)
{
	const char *p = buf, *end = buf + len;

	for (size_t ln = 0; p < end && ln <= last; ln++) {
		const char *nl = memchr(p, '\n', (size_t)(end - p));
		const char *le = nl ? nl : end;
		long col = open_quote_col(p, le);

		if (col >= 0) {
			at->line = ln;
			at->column = (size_t)col;
			return 1;
		}
		p = le + 1;
	}
	return 0;
}

static int syntax_error(struct pctx *c, int rc, const struct base_yaml_error *e,
			const char *buf, size_t len)
{
	yaml_mark_t q;

	if (rc == -ENOMEM) {
		cfg_fail_at(c, NULL, "out of memory");
		return GL_ERR_NOMEM;
	}
	if (e->type != YAML_READER_ERROR &&
	    unclosed_quote(buf, len, e->mark.line, &q))
		return cfg_fail_at(
		    c, &q,
		    "this quote is not closed on its line (the "
		    "parser then stopped at line %zu column %zu: "
		    "%s)",
		    e->mark.line + 1, e->mark.column + 1,
		    e->problem ? e->problem : "syntax error");
	if (e->context)
		return cfg_fail_at(
		    c, &e->mark, "%s (%s at line %zu column %zu)",
		    e->problem ? e->problem : "syntax error", e->context,
		    e->context_mark.line + 1, e->context_mark.column + 1);
	return cfg_fail_at(c, &e->mark, "%s",
			   e->problem ? e->problem : "syntax error");
}

/* Load the one document of @buf into @doc; a second one is an error. */
static int load_document(struct pctx *c, const char *buf, size_t len,
			 yaml_document_t *doc)
{
	struct base_yaml_error e;
	int rc = base_yaml_load(buf, len, BASE_YAML_ONE_DOC, doc, &e);

	return rc ? syntax_error(c, rc, &e, buf, len) : GL_OK;
}

/* Defaults derived from other fields; they are in range (cfg_check_table()). */
static void auto_defaults(struct pctx *c, struct re_config *cfg)
{
	int wd = 4 * cfg->period_ms;

	if (!cfg_seen_mark(c, &cfg->watchdog.controller_timeout_ms))
		cfg->watchdog.controller_timeout_ms = wd < 100 ? 100 : wd;
	/* Read-back by default wherever the protocol has it (Devantech). */
	if (!cfg_seen_mark(c, &cfg->relay.readback))
		cfg->relay.readback = cfg->relay.protocol == RE_RELAY_DEVANTECH;
}

/* Parse the loaded document into c->cfg and validate it. */
static int parse_document(struct pctx *c, yaml_document_t *doc)
{
	static const yaml_mark_t first = {0, 0, 0};
	yaml_node_t *root = yaml_document_get_root_node(doc);
	int rc;

	if (!root)
		return cfg_fail_at(c, &first, "empty configuration file");
	c->root_mark = root->start_mark;
	if (root->type != YAML_MAPPING_NODE)
		return cfg_fail_at(c, &root->start_mark,
				   "expected a mapping of settings at the top "
				   "level, got %s",
				   cfg_node_kind(root));
	/* All of them at once: a site configuration left half done should
	 * not be finished one refusal at a time. */
	rc = cfg_fill_check(c, root);
	if (!rc)
		rc = cfg_parse_map(c, root, cfg_root_fields, c->cfg,
				   "configuration");
	/* The ranges first: the defaults derived from a field (4 x period_ms)
	 * may only be computed from a value in its range (a period_ms of
	 * 1326439257 overflowed int here before it was refused). */
	if (!rc)
		rc = cfg_check_table(c, cfg_root_fields, c->cfg);
	if (rc)
		return rc;
	auto_defaults(c, c->cfg);
	return cfg_check_all(c, c->cfg);
}

int re_config_parse(const char *buf, size_t len, const char *filename,
		    struct re_config *out, char *err, size_t errlen)
{
	yaml_document_t doc;
	struct pctx *c;
	int rc;

	if (err && errlen)
		err[0] = '\0';
	if (!buf || !out)
		return GL_ERR_ARG;
	/* Context and the temporary config: too big for a small stack. */
	c = calloc(1, sizeof(*c) + sizeof(*c->cfg));
	if (!c)
		return GL_ERR_NOMEM;
	c->cfg = (struct re_config *)(c + 1);
	c->file = filename ? filename : "<config>";
	c->err = err;
	c->errlen = errlen;
	c->doc = &doc;
	re_config_defaults(c->cfg);
	rc = load_document(c, buf, len, &doc);
	if (rc)
		goto out_free_ctx;
	rc = parse_document(c, &doc);
	if (!rc)
		*out = *c->cfg; /* only now: nothing half-applied */
	yaml_document_delete(&doc);
out_free_ctx:
	free(c);
	return rc;
}

int re_config_load_file(const char *path, struct re_config *out, char *err,
			size_t errlen)
{
	char *buf = NULL;
	size_t len = 0;
	int rc, e;

	rc = base_file_read(path, CFG_FILE_MAX, &buf, &len);
	if (rc != 0) {
		e = -rc;
		if (err && errlen && rc == -EISDIR)
			snprintf(
			    err, errlen,
			    "cannot read '%s': it is a directory; give the "
			    "configuration file (e.g. %s/roboelf.yaml)",
			    path, path);
		else if (err && errlen && rc == -EINVAL)
			snprintf(err, errlen,
				 "cannot read '%s': not a regular file", path);
		else if (err && errlen)
			snprintf(err, errlen, "cannot read '%s': %s", path,
				 strerror(e));
		errno = e;
		return GL_ERR_SYS;
	}
	rc = re_config_parse(buf, len, path, out, err, errlen);
	free(buf);
	/* a caller telling "no such file" from a bad one by errno (ENOENT,
	 * e.g. left over from looking for the file) must not see a stale one */
	errno = 0;
	return rc;
}

/* ---- derived values, hash, summary ---- */

const char *re_mode_name(enum re_mode mode)
{
	return mode == RE_MODE_DEVELOPMENT ? "development" : "clinical";
}

const char *re_config_relay_port(const struct re_config *cfg)
{
	return cfg->mode == RE_MODE_CLINICAL ? cfg->relay.port_clinical
					     : cfg->relay.port_development;
}

void re_config_relay_cfg(const struct re_config *cfg, struct re_relay_cfg *out)
{
	const struct re_config_relay *r = &cfg->relay;

	memset(out, 0, sizeof(*out));
	snprintf(out->port, sizeof(out->port), "%s", re_config_relay_port(cfg));
	out->proto = r->protocol;
	out->channel = r->channel;
	out->backend = r->backend;
	out->baud = r->baud;
	out->clinical = cfg->mode == RE_MODE_CLINICAL;
	out->write_timeout_ms = r->write_timeout_ms;
	out->off_deadline_ms = r->off_deadline_ms;
	out->readback = r->readback;
	out->readback_timeout_ms = r->readback_timeout_ms;
	/* every second cycle, as before the one look: a
	 * silent board is then found within R + 3P (docs/safety.md); 1.5
	 * periods, so that a cycle's jitter never makes it every third */
	out->query_ms = cfg->period_ms + cfg->period_ms / 2;
	memcpy(out->on, r->on, sizeof(out->on));
	out->on_len = r->on_len;
	memcpy(out->off, r->off, sizeof(out->off));
	out->off_len = r->off_len;
	snprintf(out->icstation_state, sizeof(out->icstation_state), "%s",
		 r->icstation_state);
}

int re_config_absolute(struct re_config *cfg, const char *cwd, char *err,
		       size_t errlen)
{
	static const char *const names[] = {"calibration.file", "log.path",
					    "recorder.dir"};
	char *field[] = {cfg->calibration.file, cfg->log.path,
			 cfg->recorder.dir};
	char out[3][RE_PATH_MAX];

	for (int i = 0; i < 3; i++) {
		if (base_paths_absolute(cwd, field[i], out[i], RE_PATH_MAX) ==
		    0)
			continue;
		if (cwd[0] != '/')
			snprintf(err, errlen,
				 "%s: '%s' is relative to the working "
				 "directory, which is not known",
				 names[i], field[i]);
		else
			snprintf(err, errlen,
				 "%s: '%s' in '%s' is longer than %d bytes: "
				 "give an absolute path",
				 names[i], field[i], cwd, RE_PATH_MAX - 1);
		return GL_ERR_CONFIG;
	}
	for (int i = 0; i < 3; i++)
		memcpy(field[i], out[i], RE_PATH_MAX);
	return GL_OK;
}

uint64_t re_config_hash(const struct re_config *cfg)
{
	const struct re_config_axis *a;
	uint64_t h = GL_FNV64_INIT;
	char buf[256];
	int i, n;

	/* A canonical text form: independent of struct layout and padding. */
	for (i = 0; i < RE_AXES; i++) {
		a = &cfg->axes[i];
		n = snprintf(buf, sizeof(buf),
			     "axis %d name=%s step=%d travel=%d tt=%.6f "
			     "an=%d range=%.6f rt=%.6f err=%.6f mono=%.6f\n",
			     i, a->name, a->step_counts, a->travel_counts,
			     a->travel_tolerance, a->analog.input,
			     a->analog.expected_range_v,
			     a->analog.range_tolerance, a->allowed_error,
			     a->monotonic_margin_v);
		if (n > 0)
			h = gl_fnv1a64(h, buf,
				       (size_t)n < sizeof(buf)
					   ? (size_t)n
					   : sizeof(buf) - 1);
	}
	return h;
}

static size_t dump_axis(const struct re_config_axis *a, char *buf, size_t cap)
{
	int n = snprintf(
	    buf, cap,
	    "; axis %s: v %d..%d counts/s, window %d..%d ms, "
	    "step %d, travel %d counts, PID %g/%g/%g, TL %g V, "
	    "ER %d%s, OA %s (OT %d, OV %g V), pot AN%d %g V "
	    "+-%g %%, allowed error %g, persistence %d",
	    a->name, a->vmin_cps, a->vmax_cps, a->accel_start_ms,
	    a->accel_end_ms, a->step_counts, a->travel_counts, a->kp, a->ki,
	    a->kd, a->torque_limit_v, a->position_error_limit_counts,
	    a->off_on_error ? " OE" : "",
	    a->encoder_failure.enabled ? "on" : "off",
	    a->encoder_failure.time_samples, a->encoder_failure.torque_v,
	    a->analog.input, a->analog.expected_range_v,
	    a->analog.range_tolerance * 100.0, a->allowed_error,
	    a->persistence_cycles);

	return n > 0 ? (size_t)n : 0;
}

int re_config_dump(const struct re_config *cfg, char *buf, size_t cap)
{
	char dummy[1];
	size_t n, total;
	int i;

	if (!buf || !cap) {
		buf = dummy;
		cap = sizeof(dummy);
	}
	n = (size_t)snprintf(
	    buf, cap,
	    "mode %s, period %d ms, controller %s (%s, timeout %d ms, "
	    "record %s, UDP port %d), "
	    "relay %s (%s, channel %d, backend %s, %d baud%s), watchdog "
	    "%g/%g x period, controller watchdog %d ms, joystick inputs "
	    "%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d%s, invalid timeout %d "
	    "ms, calibration %s, log %s (%ld bytes x %d), hash %016" PRIx64,
	    re_mode_name(cfg->mode), cfg->period_ms, cfg->controller.address,
	    cfg->controller.model, cfg->controller.timeout_ms,
	    re_record_name(cfg->controller.record), cfg->controller.udp_port,
	    re_config_relay_port(cfg), re_relay_proto_name(cfg->relay.protocol),
	    cfg->relay.channel, cfg_backend_names[cfg->relay.backend % 3],
	    cfg->relay.baud, cfg->relay.readback ? ", read-back" : "",
	    cfg->watchdog.noncritical_factor, cfg->watchdog.critical_factor,
	    cfg->watchdog.controller_timeout_ms, cfg->joystick.inputs[0],
	    cfg->joystick.inputs[1], cfg->joystick.inputs[2],
	    cfg->joystick.inputs[3], cfg->joystick.inputs[4],
	    cfg->joystick.inputs[5], cfg->joystick.inputs[6],
	    cfg->joystick.inputs[7], cfg->joystick.inputs[8],
	    cfg->joystick.inputs[9], cfg->joystick.inputs[10],
	    cfg->joystick.inputs[11],
	    cfg->joystick.active_low ? " (active low)" : "",
	    cfg->joystick.invalid_timeout_ms, cfg->calibration.file,
	    cfg->log.path, cfg->log.max_bytes, cfg->log.keep,
	    re_config_hash(cfg));
	total = n;
	for (i = 0; i < RE_AXES; i++)
		total += dump_axis(&cfg->axes[i],
				   buf + (total < cap ? total : cap - 1),
				   total < cap ? cap - total : 1);
	return (int)total;
}
