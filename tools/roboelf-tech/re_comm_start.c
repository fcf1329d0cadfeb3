/*
 * re_comm_start.c - what the commissioning run needs before its first step.
 * See re_comm_start.h.
 */
#include "re_comm_start.h"

#include <stdio.h>
#include <stdlib.h>

#include "re_comm_find.h"

/* Where this run's discovery probe goes (re_comm_start()). */
static struct {
	const char *addr;
	int port;
} find_to;

/* The configured address did not answer (@why): list the controllers
 * that answer the discovery probe and, on a terminal, let the technician
 * pick one (never chosen silently). Return 0 with a->cfg's address set to
 * the choice, or EXIT_CONNECT. */
static int find(struct app *a, const char *why)
{
	static struct re_comm_found list[RE_COMM_FIND_MAX];
	const char *bc = find_to.addr ? find_to.addr : RE_COMM_FIND_BCAST;
	int port = find_to.port ? find_to.port : RE_COMM_FIND_PORT;
	char line[32], *end;
	long k;
	int n;

	re_start_progress(
	    a,
	    "%s; looking for Galil controllers (discovery probe to "
	    "UDP %s:%d, %d ms)",
	    why, bc, port, RE_COMM_FIND_MS);
	n = re_comm_find(bc, (unsigned)port, RE_COMM_FIND_MS, list,
			 RE_COMM_FIND_MAX, a->err, sizeof(a->err));
	if (n < 0)
		return re_start_fail(a, a->err);
	if (n == 0)
		return re_start_fail(
		    a, "no Galil controller answered: check the "
		       "controller's power and Ethernet cable, and "
		       "controller.address in the configuration");
	for (int i = 0; i < n; i++)
		re_console_msg(&a->con, "  %d) %s  %s", i + 1, list[i].addr,
			       list[i].what);
	if (!a->con.tty_in)
		return re_start_fail(
		    a, "the configured controller does not answer; "
		       "the controllers listed above do: run again "
		       "with --galil ADDRESS");
	re_console_msg(&a->con, "connect to which one (1-%d, Enter: none)?", n);
	if (!fgets(line, sizeof(line), stdin) ||
	    (k = strtol(line, &end, 10)) < 1 || k > n || (*end && *end != '\n'))
		return re_start_fail(a, "no controller chosen");
	snprintf(a->cfg.controller.address, sizeof(a->cfg.controller.address),
		 "%s", list[k - 1].addr);
	re_start_progress(a,
			  "using %s (chosen from the list; set "
			  "controller.address or --galil for the next time)",
			  a->cfg.controller.address);
	return 0;
}

int re_comm_start(struct app *a, const char *find_addr, int find_port)
{
	static const struct re_bringup b = {find, 0, NULL};
	int rc;

	find_to.addr = find_addr;
	find_to.port = find_port;
	rc = re_start_bringup(a, &b);

	if (rc || re_sig.quit)
		return rc ? rc : EXIT_CONNECT;
	re_plan_make(&a->cfg, 0, &a->plan);
	re_start_progress(a, "halting the controller program; every motor off");
	if (re_ctl_halt(&a->io, a->err, sizeof(a->err)) ||
	    re_ctl_configure(&a->io, &a->cfg, &a->plan, a->err, sizeof(a->err)))
		return re_start_fail(a, a->err);
	re_start_progress(
	    a, "controller configured and read back; motor power off");
	return 0;
}
