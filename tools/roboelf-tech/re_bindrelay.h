/*
 * re_bindrelay.h - `roboelf-tech bind-relay`: the E-stop relay board bound
 * to this robot by its USB serial number. The USB serial ports are listed,
 * the board chosen (the one there is, or the one of --serial), and the
 * udev rule that names that one board /dev/roboelf-relay written whole or
 * not at all (base_durable_write()); the technician is told how to reload
 * udev (it is not reloaded here) and which relay.serial to configure
 * (docs/technician.md, section 10; re_bind.h).
 *
 * The listing is a parameter, so that tests give their own ports and
 * never touch a real serial device; re_bindrelay_list_sp() is the real one.
 */
#ifndef RE_BINDRELAY_H
#define RE_BINDRELAY_H

#include <stddef.h>
#include <stdio.h>

#include "re_bind.h"

/* Where the rule goes: udev reads /etc/udev/rules.d whatever the
 * installation's prefix; the same name masks the package's rule in
 * /lib/udev/rules.d. */
#define RE_BINDRELAY_RULES "/etc/udev/rules.d/60-roboelf-relay.rules"
#define RE_BINDRELAY_PORTS 32 /* USB serial ports listed at most */

/*
 * A listing of the USB serial ports: up to @cap into @ports, their number
 * in *@n. Return: GL_OK; else a gl_err code with the reason in @err.
 */
typedef int (*re_bindrelay_list_fn)(struct re_bind_port *ports, size_t cap,
				    size_t *n, char *err, size_t errlen);

struct re_bindrelay_opts {
	const char *serial;	/* --serial: the board to bind; NULL: the one
				 * there is */
	const char *rules_file; /* --rules-file; NULL: RE_BINDRELAY_RULES */
};

/*
 * re_bindrelay_list_sp() - the USB serial ports libserialport lists
 * (sp_list_ports; transport USB only), with their vendor and product ids,
 * serial numbers ("" when none) and descriptions. Reads sysfs; opens no
 * port. Return: GL_OK; GL_ERR_SYS (the listing failed), GL_ERR_OVERFLOW
 * (more than @cap), each with a message in @err.
 */
int re_bindrelay_list_sp(struct re_bind_port *ports, size_t cap, size_t *n,
			 char *err, size_t errlen);

/*
 * re_bindrelay_run() - bind-relay: list the ports with @list, print them on
 * @out, choose the board (re_bind_choose()), write its rule into
 * @o->rules_file, and print the rule and the next steps on @out. A refusal
 * is printed on @errf ("roboelf-tech: error: ...") and leaves the rules
 * file untouched.
 * Return: the exit code: 0 written; 2 the rules file cannot be written;
 *         3 no single board (none, several, none of that serial number)
 *         or its serial number refused.
 */
int re_bindrelay_run(const struct re_bindrelay_opts *o,
		     re_bindrelay_list_fn list, FILE *out, FILE *errf);

#endif /* RE_BINDRELAY_H */
