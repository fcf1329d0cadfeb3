/*
 * re_bindrelay.c - `roboelf-tech bind-relay`: the relay board's udev rule
 * by its USB serial number. See re_bindrelay.h.
 */
#include "re_bindrelay.h"

#include <errno.h>
#include <libserialport.h>
#include <stdio.h>
#include <string.h>

#include "base_durable.h"
#include "gl_err.h"

/* Exit codes, as roboelf-tech's (roboelf-tech.1). */
#define EXIT_WRITE 2 /* the rules file cannot be written */
#define EXIT_BOARD 3 /* no single relay board, or its serial refused */

#define RULES_MODE 0644 /* udev's rules are world-readable */

/* One port of libserialport's list into @p; names longer than the fields
 * are cut (they are shown, never matched). */
static void port_from_sp(struct sp_port *sp, struct re_bind_port *p)
{
	const char *s;

	memset(p, 0, sizeof(*p));
	snprintf(p->name, sizeof(p->name), "%s", sp_get_port_name(sp));
	s = sp_get_port_description(sp);
	snprintf(p->desc, sizeof(p->desc), "%s", s ? s : "");
	s = sp_get_port_usb_serial(sp);
	snprintf(p->serial, sizeof(p->serial), "%s", s ? s : "");
	if (sp_get_port_usb_vid_pid(sp, &p->vid, &p->pid) != SP_OK)
		p->vid = p->pid = -1;
}

int re_bindrelay_list_sp(struct re_bind_port *ports, size_t cap, size_t *n,
			 char *err, size_t errlen)
{
	struct sp_port **list = NULL;
	int rc = GL_OK;
	size_t i;

	*n = 0;
	if (sp_list_ports(&list) != SP_OK) {
		snprintf(err, errlen, "cannot list the serial ports: %s",
			 strerror(errno));
		return GL_ERR_SYS;
	}
	for (i = 0; list[i]; i++) {
		if (sp_get_port_transport(list[i]) != SP_TRANSPORT_USB)
			continue;
		if (*n == cap) {
			snprintf(err, errlen,
				 "more than %zu USB serial ports: unplug every "
				 "one but the relay board and run again",
				 cap);
			rc = GL_ERR_OVERFLOW;
			break;
		}
		port_from_sp(list[i], &ports[(*n)++]);
	}
	sp_free_port_list(list);
	return rc;
}

/* The ports found, one line each, shown safely (re_bind_shown()). */
static void print_ports(const struct re_bind_port *ports, size_t n, FILE *out)
{
	char name[RE_BIND_NAME_MAX], desc[RE_BIND_DESC_MAX];
	char shown[RE_BIND_SERIAL_MAX], serial[RE_BIND_SERIAL_MAX + 2];
	size_t i;

	fprintf(out, "bind-relay: %zu USB serial port%s found%s\n", n,
		n == 1 ? "" : "s", n ? ":" : "");
	for (i = 0; i < n; i++) {
		const struct re_bind_port *p = &ports[i];

		if (p->serial[0])
			snprintf(
			    serial, sizeof(serial), "'%s'",
			    re_bind_shown(p->serial, shown, sizeof(shown)));
		else
			snprintf(serial, sizeof(serial), "none");
		fprintf(out, "  %s  USB %04x:%04x  serial number %s  %s\n",
			re_bind_shown(p->name, name, sizeof(name)),
			(unsigned)p->vid & 0xffff, (unsigned)p->pid & 0xffff,
			serial, re_bind_shown(p->desc, desc, sizeof(desc)));
	}
}

/* The rule written, and what the technician does next. */
static void print_done(const struct re_bind_port *p, const char *path,
		       const char *rule, FILE *out)
{
	const char *line = strstr(rule, "SUBSYSTEM==");
	char name[RE_BIND_NAME_MAX];
	const char *node = re_bind_shown(p->name, name, sizeof(name));

	if (strrchr(node, '/'))
		node = strrchr(node, '/') + 1;
	fprintf(
	    out,
	    "bind-relay: the relay board: %s, USB %04x:%04x, serial number "
	    "'%s'\n"
	    "bind-relay: wrote %s:\n%s"
	    "bind-relay: next, as root: udevadm control --reload && "
	    "udevadm trigger\n"
	    "bind-relay: then check: ls -l /dev/" RE_BIND_SYMLINK
	    " (a link to %s)\n"
	    "bind-relay: and set in the configuration (relay:) serial: %s\n",
	    name, (unsigned)p->vid, (unsigned)p->pid, p->serial, path,
	    line ? line : rule, node, p->serial);
}

/* Write @rule to @path whole or not at all. */
static int write_rule(const char *path, const char *rule, FILE *errf)
{
	int rc = base_durable_write(path, rule, strlen(rule), RULES_MODE);

	if (!rc)
		return 0;
	fprintf(errf, "roboelf-tech: error: cannot write '%s': %s%s\n", path,
		strerror(-rc),
		rc == -EACCES || rc == -EPERM
		    ? " (run it as root: sudo roboelf-tech bind-relay)"
		    : "");
	return EXIT_WRITE;
}

int re_bindrelay_run(const struct re_bindrelay_opts *o,
		     re_bindrelay_list_fn list, FILE *out, FILE *errf)
{
	static struct re_bind_port ports[RE_BINDRELAY_PORTS];
	const char *path = o->rules_file ? o->rules_file : RE_BINDRELAY_RULES;
	char err[RE_BIND_ERR_MAX], rule[RE_BIND_RULE_MAX];
	size_t n = 0, k = 0;
	int rc;

	rc = list(ports, RE_BINDRELAY_PORTS, &n, err, sizeof(err));
	if (rc != GL_OK) {
		fprintf(errf, "roboelf-tech: error: %s\n", err);
		return EXIT_BOARD;
	}
	print_ports(ports, n, out);
	if (re_bind_choose(ports, n, o->serial, &k, err, sizeof(err)) !=
		GL_OK ||
	    re_bind_rule(&ports[k], rule, sizeof(rule), err, sizeof(err)) < 0) {
		fprintf(errf, "roboelf-tech: error: %s\n", err);
		return EXIT_BOARD;
	}
	rc = write_rule(path, rule, errf);
	if (!rc)
		print_done(&ports[k], path, rule, out);
	return rc;
}
