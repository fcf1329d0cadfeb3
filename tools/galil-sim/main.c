/*
 * main.c - galil-sim: a DMC-4030 simulator executing DMC programs against a
 * simulated RoboELF robot (docs/galil-sim.md, galil-sim(1)).
 *
 * Exit status: 0 after "quit" or SIGTERM/SIGINT; 1 when the ports or the
 * relay cannot be set up or the loop fails; 2 for a usage error or a bad
 * plant file.
 */
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base_version.h"
#include "ctrl.h"
#include "gl_err.h"
#include "sim.h"
#include "sim_bench.h"
#include "sim_net.h"
#include "sim_plant.h"
#include "sim_relay.h"

#define SIM_VERSION	     ROBOELF_VERSION
#define DEFAULT_PORT	     23023
#define DEFAULT_CONTROL_PORT 23024
#define DEFAULT_RELAY_LINK   "/tmp/roboelf-relay"
#define DEFAULT_PROTOCOL     "devantech"
#define ERR_LEN		     512
#define MAX_REPEAT	     16 /* --miswire given at most this often */

struct opts {
	int port, control_port;
	int disc_port;		 /* --disc-port N, -1: no discovery answer */
	int udp_port;		 /* --udp-port N, -1: no UDP command port */
	const char *listen_addr; /* --listen, NULL: 127.0.0.1 */
	const char *plant, *relay_link, *protocol;
	unsigned long seed;
	int have_seed, verbose;
	double bench_s;	      /* > 0: run the speed bench instead */
	int no_amp_uv;	      /* --no-amp-undervoltage */
	int power_output;     /* --power-output N, -1: the plant file's */
	unsigned long serial; /* --serial N, 0: the default */
	const char *miswire[MAX_REPEAT]; /* --miswire SPEC, in order */
	int n_miswire;
	unsigned deviate; /* --deviate NAME: CTRL_DEV_* bits */
};

static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
	(void)sig;
	stop = 1;
}

static void usage(FILE *f)
{
	fprintf(
	    f,
	    "usage: galil-sim [--port N] [--control-port M] [--listen ADDR]\n"
	    "                 [--disc-port N] [--udp-port N] [--plant FILE]\n"
	    "                 [--relay-link PATH | --no-relay-link]\n"
	    "                 [--relay-protocol NAME] [--seed N] [--verbose]\n"
	    "                 [--no-amp-undervoltage] [--power-output N]\n"
	    "                 [--serial N] [--miswire SPEC]... [--deviate "
	    "NAME]...\n"
	    "       galil-sim --bench [SECONDS]\n"
	    "       galil-sim --help | --version\n"
	    "  --port N            command port (default %d, 0 = "
	    "any)\n"
	    "  --control-port M    control port (default %d, 0 = any)\n"
	    "  --listen ADDR       IPv4 address of both ports (default "
	    "127.0.0.1)\n"
	    "  --disc-port N       answer the controller discovery probe on "
	    "UDP port N\n"
	    "                      of ADDR (Galil's is 50000; 0 = any; "
	    "default: off)\n"
	    "  --udp-port N        also answer commands on UDP port N of ADDR "
	    "(UDP handles,\n"
	    "                      the DR record stream; 0 = any; default: "
	    "off)\n"
	    "  --plant FILE        robot model (default: built in, see "
	    "config/plant.yaml)\n"
	    "  --relay-link PATH   symbolic link to the relay pty (default "
	    "%s)\n"
	    "  --no-relay-link     no link; the pty path is in the ready line\n"
	    "  --relay-protocol P  devantech, icstation, lcus or kmtronic "
	    "(default %s)\n"
	    "  --seed N            potentiometer noise seed (default: plant "
	    "file, 1)\n"
	    "  --verbose           print every event on stderr\n"
	    "  --no-amp-undervoltage  losing motor power is not reported to "
	    "the controller\n"
	    "  --power-output N    motor power also needs controller output "
	    "N (1..8; 0 = none)\n"
	    "  --serial N          the controller's serial number, MG _BN "
	    "(default 403001)\n"
	    "  --miswire SPEC      wire the robot wrong on purpose: "
	    "encoder-reversed:A,\n"
	    "                      limits-swapped:B, relay-unwired, "
	    "pot-reversed:C,\n"
	    "                      joystick-swap:5,7, dead-input:6, "
	    "joystick-polarity\n"
	    "  --deviate NAME      answer differently from the reference: "
	    "mg-join,\n"
	    "                      dm-exists, qr-header, ul-trim, mo-moving,\n"
	    "                      za-16bit\n"
	    "  --bench [SECONDS]   measure virtual-time speed with 8 busy "
	    "threads\n",
	    DEFAULT_PORT, DEFAULT_CONTROL_PORT, DEFAULT_RELAY_LINK,
	    DEFAULT_PROTOCOL);
}

static int parse_ulong(const char *s, unsigned long max, unsigned long *out)
{
	char *end;

	errno = 0;
	if (!*s || *s == '-')
		return -1;
	*out = strtoul(s, &end, 10);
	return *end || errno || *out > max ? -1 : 0;
}

static int parse_serial(const char *arg, struct opts *o)
{
	if (parse_ulong(arg, 999999999UL, &o->serial) < 0 || o->serial == 0) {
		fprintf(stderr,
			"galil-sim: bad serial number '%s' (1..999999999)\n",
			arg);
		return -1;
	}
	return 0;
}

/* --miswire SPEC: checked on the default robot now, applied after the
 * plant file is loaded. */
static int parse_miswire(const char *arg, struct opts *o)
{
	struct sim_plant_cfg cfg;
	char err[ERR_LEN];

	sim_plant_cfg_default(&cfg);
	if (sim_plant_cfg_miswire(&cfg, arg, err, sizeof(err)) < 0) {
		fprintf(stderr, "galil-sim: %s\n", err);
		return -1;
	}
	if (o->n_miswire == MAX_REPEAT) {
		fprintf(stderr, "galil-sim: more than %d --miswire\n",
			MAX_REPEAT);
		return -1;
	}
	o->miswire[o->n_miswire++] = arg;
	return 0;
}

static int parse_opt(int c, const char *arg, struct opts *o)
{
	unsigned long v;
	char *end;

	switch (c) {
	case 'p':
	case 'c':
	case 'D':
	case 'U':
		if (parse_ulong(arg, 65535, &v) < 0) {
			fprintf(stderr, "galil-sim: bad port '%s'\n", arg);
			return -1;
		}
		*(c == 'p'   ? &o->port
		  : c == 'c' ? &o->control_port
		  : c == 'U' ? &o->udp_port
			     : &o->disc_port) = (int)v;
		return 0;
	case 'P': o->plant = arg; return 0;
	case 'L': o->listen_addr = arg; return 0;
	case 'l': o->relay_link = arg; return 0;
	case 'n': o->relay_link = ""; return 0;
	case 'r': o->protocol = arg; return 0;
	case 'v': o->verbose = 1; return 0;
	case 'u': o->no_amp_uv = 1; return 0;
	case 'o':
		if (parse_ulong(arg, SIM_PLANT_POWER_OUTPUTS, &v) < 0) {
			fprintf(stderr,
				"galil-sim: bad power output '%s' (0..%d)\n",
				arg, SIM_PLANT_POWER_OUTPUTS);
			return -1;
		}
		o->power_output = (int)v;
		return 0;
	case 'S': return parse_serial(arg, o);
	case 'm': return parse_miswire(arg, o);
	case 'd':
		if (!sim_deviation_bit(arg)) {
			fprintf(stderr,
				"galil-sim: unknown deviation '%s' (mg-join, "
				"dm-exists, qr-header, ul-trim, mo-moving, "
				"za-16bit)\n",
				arg);
			return -1;
		}
		o->deviate |= sim_deviation_bit(arg);
		return 0;
	case 's':
		if (parse_ulong(arg, 0xFFFFFFFFUL, &o->seed) < 0) {
			fprintf(stderr, "galil-sim: bad seed '%s'\n", arg);
			return -1;
		}
		o->have_seed = 1;
		return 0;
	case 'b':
		o->bench_s = arg ? strtod(arg, &end) : 10;
		if (arg && (*end || !(o->bench_s > 0 && o->bench_s <= 3600))) {
			fprintf(stderr, "galil-sim: bad bench time '%s'\n",
				arg);
			return -1;
		}
		return 0;
	default: return -1;
	}
}

/* Return: 0 to run, 1 to exit 0 (help, version), -1 usage error. */
static int parse_args(int argc, char **argv, struct opts *o)
{
	static const struct option longopts[] = {
	    {"port", required_argument, NULL, 'p'},
	    {"control-port", required_argument, NULL, 'c'},
	    {"listen", required_argument, NULL, 'L'},
	    {"disc-port", required_argument, NULL, 'D'},
	    {"udp-port", required_argument, NULL, 'U'},
	    {"plant", required_argument, NULL, 'P'},
	    {"relay-link", required_argument, NULL, 'l'},
	    {"no-relay-link", no_argument, NULL, 'n'},
	    {"relay-protocol", required_argument, NULL, 'r'},
	    {"seed", required_argument, NULL, 's'},
	    {"verbose", no_argument, NULL, 'v'},
	    {"no-amp-undervoltage", no_argument, NULL, 'u'},
	    {"power-output", required_argument, NULL, 'o'},
	    {"serial", required_argument, NULL, 'S'},
	    {"miswire", required_argument, NULL, 'm'},
	    {"deviate", required_argument, NULL, 'd'},
	    {"bench", optional_argument, NULL, 'b'},
	    {"help", no_argument, NULL, 'h'},
	    {"version", no_argument, NULL, 'V'},
	    {NULL, 0, NULL, 0},
	};
	enum sim_relay_proto proto;
	int c;

	while ((c = getopt_long(argc, argv, "", longopts, NULL)) != -1) {
		if (c == 'h') {
			usage(stdout);
			return 1;
		}
		if (c == 'V') {
			printf("galil-sim %s\n", SIM_VERSION);
			return 1;
		}
		if (c == 'b' && !optarg && optind < argc &&
		    argv[optind][0] != '-')
			optarg = argv[optind++]; /* "--bench 5" */
		if (parse_opt(c, optarg, o) < 0) {
			fprintf(stderr, "try 'galil-sim --help'\n");
			return -1;
		}
	}
	if (optind < argc) {
		fprintf(stderr, "galil-sim: unexpected argument '%s'\n",
			argv[optind]);
		return -1;
	}
	if (sim_relay_proto_parse(o->protocol, &proto) < 0) {
		fprintf(stderr,
			"galil-sim: unknown relay protocol '%s' "
			"(devantech, icstation, lcus, kmtronic)\n",
			o->protocol);
		return -1;
	}
	return 0;
}

static void print_event(void *ud, double t_ms, const char *text)
{
	(void)ud;
	fprintf(stderr, "galil-sim: %.3f %s\n", t_ms, text);
}

static void set_signals(void)
{
	struct sigaction sa;

	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal; /* no SA_RESTART: poll() wakes up */
	sigemptyset(&sa.sa_mask);
	sigaction(SIGTERM, &sa, NULL);
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGHUP, &sa, NULL);
	signal(SIGPIPE, SIG_IGN);
}

static int run_bench(double seconds)
{
	struct sim_bench_result r;
	char err[ERR_LEN];

	if (sim_bench_threads(8, seconds * 1000, &r, err, sizeof(err)) < 0) {
		fprintf(stderr, "galil-sim: bench failed: %s\n", err);
		return 1;
	}
	printf("galil-sim virtual time: %.1f x real time (8 busy threads, "
	       "%.0f ms simulated in %.1f ms, %.0f thread loops)\n",
	       r.speed, r.sim_ms, r.real_ms, r.loops);
	return 0;
}

/* The command and control ports, and the discovery and UDP ports when asked.
 * Return: 0, or 1 (the message is printed). */
static int open_ports(struct sim *s, const struct opts *o, struct sim_net **net)
{
	char err[ERR_LEN];

	if (sim_net_open(net, s, o->listen_addr, o->port, o->control_port, err,
			 sizeof(err)) < 0) {
		fprintf(stderr, "galil-sim: %s\n", err);
		return 1;
	}
	if (o->disc_port >= 0 &&
	    sim_net_open_disc(*net, o->listen_addr, o->disc_port, err,
			      sizeof(err)) < 0) {
		fprintf(stderr, "galil-sim: %s\n", err);
		sim_net_free(*net);
		return 1;
	}
	if (o->udp_port >= 0 &&
	    sim_net_open_udp(*net, o->listen_addr, o->udp_port, err,
			     sizeof(err)) < 0) {
		fprintf(stderr, "galil-sim: %s\n", err);
		sim_net_free(*net);
		return 1;
	}
	return 0;
}

/* The ready line; " disc <port>" / " udp <port>" only when on, so that the
 * line stays what it was for everything that does not ask for it. */
static void print_ready(struct sim *s, const struct opts *o,
			const struct sim_net *net)
{
	printf("galil-sim: listening on %s:%d control %d relay %s",
	       o->listen_addr ? o->listen_addr : "127.0.0.1", sim_net_port(net),
	       sim_net_control_port(net), sim_relay_tty(sim_get_relay(s)));
	if (sim_net_disc_port(net) > 0)
		printf(" disc %d", sim_net_disc_port(net));
	if (sim_net_udp_port(net) > 0)
		printf(" udp %d", sim_net_udp_port(net));
	printf("\n");
	fflush(stdout);
}

static int serve(struct sim *s, const struct opts *o)
{
	struct sim_net *net;
	struct sim_net_stats st;
	char err[ERR_LEN];
	int rc;

	if (open_ports(s, o, &net))
		return 1;
	print_ready(s, o, net);
	rc = sim_net_run(net, &stop, err, sizeof(err));
	if (rc < 0)
		fprintf(stderr, "galil-sim: %s\n", err);
	sim_net_stats(net, &st);
	if (o->verbose)
		fprintf(stderr,
			"galil-sim: %llu samples, %llu late wake-ups "
			"(at most %llu samples due)\n",
			(unsigned long long)st.samples,
			(unsigned long long)st.late_wakeups,
			(unsigned long long)st.max_due);
	sim_net_free(net);
	return rc < 0 ? 1 : 0;
}

int main(int argc, char **argv)
{
	struct opts o = {
	    .port = DEFAULT_PORT,
	    .control_port = DEFAULT_CONTROL_PORT,
	    .disc_port = -1,
	    .udp_port = -1,
	    .relay_link = DEFAULT_RELAY_LINK,
	    .protocol = DEFAULT_PROTOCOL,
	    .power_output = -1,
	};
	char err[ERR_LEN];
	struct sim *s;
	int rc = parse_args(argc, argv, &o);

	if (rc != 0)
		return rc > 0 ? 0 : 2;
	if (o.bench_s > 0)
		return run_bench(o.bench_s);
	set_signals();
	if (sim_new_serial(&s, o.plant, (long)o.serial, err, sizeof(err)) < 0) {
		fprintf(stderr, "%s\n", err);
		return 2;
	}
	if (o.have_seed)
		sim_seed(s, o.seed);
	if (o.no_amp_uv)
		sim_plant_set_amp_undervoltage(sim_get_plant(s), 0);
	if (o.power_output >= 0)
		sim_plant_set_power_output(sim_get_plant(s), o.power_output);
	for (int i = 0; i < o.n_miswire; i++) {
		if (sim_plant_miswire(sim_get_plant(s), o.miswire[i], err,
				      sizeof(err)) < 0) {
			fprintf(stderr, "galil-sim: --miswire %s: %s\n",
				o.miswire[i], err);
			sim_free(s);
			return 2;
		}
	}
	ctrl_set_deviate(sim_ctrl(s), o.deviate);
	if (o.verbose)
		sim_set_event_hook(s, print_event, NULL);
	rc = sim_attach_relay(s, o.protocol, o.relay_link, err, sizeof(err));
	if (rc < 0) {
		fprintf(stderr, "galil-sim: %s\n", err);
		sim_free(s);
		return 1;
	}
	rc = serve(s, &o);
	sim_free(s);
	return rc;
}
