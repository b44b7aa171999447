// plume view INPUT [-o DIR] [--serve PORT]
//
// Writes a web page that shows plume's .glb files (a feather, a coat, a
// simulation) in a browser: the viewer built from viewer/ (three.js, bundled by
// esbuild into one classic script) copied beside a models.js that lists the
// files. Chromium does not let a file:// page fetch other files, so by default
// the .glb files are embedded in models.js as base64 and the page opens from
// disk, offline. With --serve the page fetches them from a small HTTP server on
// 127.0.0.1 instead (no size limit, no copy), which runs until interrupted.
#define _XOPEN_SOURCE 700 // realpath
#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <netinet/in.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

#include "cli.h"

// Chromium's longest string is 2^29 - 24 characters: an embedded file's base64
// must stay below it, with room for the page's own copy while decoding.
#define VIEW_EMBED_LIMIT ((long long)256 << 20)
#define VIEW_MAX_FILES 24

static const char *const viewer_assets[] = {"index.html", "plume-viewer.js", "LICENSE.three.txt"};

void cli_help_view(void)
{
	puts("Usage: plume view INPUT [options]\n"
	     "\n"
	     "Writes a web page that shows plume's glTF files in a browser (three.js):\n"
	     "orbit with the mouse; for an animated file (a simulation) play/pause, a frame\n"
	     "slider and a frame counter. INPUT is a .glb file or a folder whose .glb files\n"
	     "are all listed (a menu picks one). The page is\n"
	     "  DIR/index.html        open it in a browser\n"
	     "  DIR/models.js         the .glb files, embedded as base64 (or their URLs)\n"
	     "  DIR/plume-viewer.js   the viewer (three.js, MIT licence in LICENSE.three.txt)\n"
	     "where DIR is INPUT/view (INPUT's folder/view for a file) unless -o says.\n"
	     "The embedded page opens from disk with no server and no network. Files over\n"
	     "256 MB cannot be embedded: use --serve.\n"
	     "\n"
	     "Options:\n"
	     "  -o, --output DIR     where to write the page\n"
	     "      --serve PORT     do not embed: serve the page and the files on\n"
	     "                       http://127.0.0.1:PORT/ (this machine only) until Ctrl-C\n"
	     "      --viewer DIR     the built viewer (default: $PLUME_VIEWER_DIR, else\n"
	     "                       viewer/ beside the plume binary in the build tree, else\n"
	     "                       ../share/plume/viewer from it once installed)\n"
	     "  -h, --help           this help\n"
	     "\n"
	     "The viewer is built by `make` when node and npm are present (see README).");
}

typedef struct view_file {
	char path[PATH_MAX];
	char name[256];
	long long size;
} view_file;

static bool ends_with(const char *text, const char *suffix)
{
	size_t n = strlen(text), m = strlen(suffix);
	return n >= m && strcmp(text + n - m, suffix) == 0;
}

static int compare_files(const void *a, const void *b)
{
	return strcmp(((const view_file *)a)->name, ((const view_file *)b)->name);
}

/// A .glb file starts with the GLB header (glTF 2.0, 4.4.2): the magic "glTF", version 2
/// and the file's length, little-endian; anything else (a text file named .glb, a file cut
/// short) is refused before the page is written, rather than failing in the browser.
static plume_status check_glb_header(const char *path, long long size, plume_error *err)
{
	unsigned char header[12];
	FILE *file = fopen(path, "rb");
	if (file == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: %s", path, strerror(errno));
	size_t n = fread(header, 1, sizeof header, file);
	fclose(file);
	uint32_t version = 0, length = 0;
	for (int i = 3; i >= 0; --i) {
		version = version << 8 | header[4 + i];
		length = length << 8 | header[8 + i];
	}
	if (n < sizeof header || memcmp(header, "glTF", 4) != 0)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "%s: not a glTF binary (a .glb file starts with the bytes \"glTF\"); plume view shows "
		                       ".glb files",
		                       path);
	if (version != 2)
		return plume_error_set(err, PLUME_ERROR_SPEC, "%s: glTF binary version %u; plume view shows version 2", path,
		                       version);
	if ((long long)length != size)
		return plume_error_set(err, PLUME_ERROR_SPEC,
		                       "%s: its GLB header gives %u bytes, but the file has %lld (cut short, or not one "
		                       "file)",
		                       path, length, size);
	return PLUME_OK;
}

// The .glb files of INPUT (a file or a folder's own entries), sorted by name.
static plume_status find_inputs(const char *input, view_file *files, int *count, char *default_dir, size_t size,
                                plume_error *err)
{
	struct stat info;
	*count = 0;
	if (stat(input, &info) != 0)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: %s", input, strerror(errno));
	if (S_ISREG(info.st_mode)) {
		if (!ends_with(input, ".glb"))
			return plume_error_set(err, PLUME_ERROR_IO, "%s: not a .glb file (glTF binary)", input);
		const char *slash = strrchr(input, '/');
		snprintf(files[0].path, sizeof files[0].path, "%s", input);
		snprintf(files[0].name, sizeof files[0].name, "%s", slash != NULL ? slash + 1 : input);
		files[0].size = info.st_size;
		*count = 1;
		plume_status status = check_glb_header(input, info.st_size, err);
		if (status != PLUME_OK)
			return status;
		if (slash != NULL)
			snprintf(default_dir, size, "%.*s/view", (int)(slash - input), input);
		else
			snprintf(default_dir, size, "view");
		return PLUME_OK;
	}
	DIR *dir = opendir(input);
	if (dir == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: %s", input, strerror(errno));
	struct dirent *entry;
	while ((entry = readdir(dir)) != NULL) {
		if (!ends_with(entry->d_name, ".glb") || strlen(entry->d_name) >= sizeof files[0].name)
			continue;
		char path[PATH_MAX];
		snprintf(path, sizeof path, "%s/%s", input, entry->d_name);
		if (stat(path, &info) != 0 || !S_ISREG(info.st_mode))
			continue;
		if (*count == VIEW_MAX_FILES) {
			closedir(dir);
			return plume_error_set(err, PLUME_ERROR_IO, "%s: more than %d .glb files; give one file as INPUT", input,
			                       VIEW_MAX_FILES);
		}
		view_file *f = &files[(*count)++];
		snprintf(f->path, sizeof f->path, "%s", path);
		snprintf(f->name, sizeof f->name, "%s", entry->d_name);
		f->size = info.st_size;
		plume_status status = check_glb_header(path, info.st_size, err);
		if (status != PLUME_OK) {
			closedir(dir);
			return status;
		}
	}
	closedir(dir);
	if (*count == 0)
		return plume_error_set(err, PLUME_ERROR_IO,
		                       "%s: no .glb file in this folder (write one with --format glb, or simulate)", input);
	qsort(files, (size_t)*count, sizeof files[0], compare_files);
	int length = (int)strlen(input);
	while (length > 1 && input[length - 1] == '/') // "sim/" -> "sim/view", not "sim//view"
		--length;
	snprintf(default_dir, size, "%.*s/view", length, input);
	return PLUME_OK;
}

static bool has_assets(const char *dir)
{
	for (size_t i = 0; i < sizeof viewer_assets / sizeof viewer_assets[0]; ++i) {
		char path[PATH_MAX + 64];
		if (snprintf(path, sizeof path, "%s/%s", dir, viewer_assets[i]) >= (int)sizeof path || access(path, R_OK) != 0)
			return false;
	}
	return true;
}

// The built viewer: --viewer, $PLUME_VIEWER_DIR, then beside the binary (build
// tree: build/viewer) and the install layout (<prefix>/share/plume/viewer).
static plume_status find_viewer(const char *option, char *out, size_t size, plume_error *err)
{
	char tried[3][PATH_MAX + 32];
	int n = 0;
	const char *env = getenv("PLUME_VIEWER_DIR");
	const char *given = option != NULL ? option : (env != NULL && env[0] != '\0' ? env : NULL);
	if (given != NULL) {
		if (has_assets(given) && snprintf(out, size, "%s", given) < (int)size)
			return PLUME_OK;
		return plume_error_set(err, PLUME_ERROR_IO, "%s (%s): no built viewer there (index.html, plume-viewer.js)",
		                       given, option != NULL ? "--viewer" : "PLUME_VIEWER_DIR");
	}
	char exe[PATH_MAX];
	ssize_t length = readlink("/proc/self/exe", exe, sizeof exe - 1);
	if (length > 0) {
		exe[length] = '\0';
		char *slash = strrchr(exe, '/');
		if (slash != NULL)
			*slash = '\0';
		snprintf(tried[n++], sizeof tried[0], "%s/viewer", exe);
		snprintf(tried[n++], sizeof tried[0], "%s/../share/plume/viewer", exe);
	}
	for (int i = 0; i < n; ++i) {
		if (has_assets(tried[i]) && snprintf(out, size, "%s", tried[i]) < (int)size)
			return PLUME_OK;
	}
	return plume_error_set(err, PLUME_ERROR_IO,
	                       "the browser viewer is not built (looked in %s and %s): install node and npm, then run "
	                       "`make viewer` (README), or give --viewer DIR",
	                       n > 0 ? tried[0] : "?", n > 1 ? tried[1] : "?");
}

static plume_status copy_file(const char *from, const char *to, plume_error *err)
{
	FILE *in = fopen(from, "rb");
	if (in == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: %s", from, strerror(errno));
	FILE *out = fopen(to, "wb");
	if (out == NULL) {
		fclose(in);
		return plume_error_set(err, PLUME_ERROR_IO, "%s: %s", to, strerror(errno));
	}
	char buffer[1 << 16];
	size_t n;
	bool ok = true;
	while ((n = fread(buffer, 1, sizeof buffer, in)) > 0)
		ok = ok && fwrite(buffer, 1, n, out) == n;
	ok = ok && !ferror(in);
	fclose(in);
	ok = (fclose(out) == 0) && ok;
	return ok ? PLUME_OK : plume_error_set(err, PLUME_ERROR_IO, "%s: cannot copy to %s", from, to);
}

// A file name as a JavaScript string literal (JSON escaping).
static void write_js_string(FILE *out, const char *text)
{
	fputc('"', out);
	for (const unsigned char *c = (const unsigned char *)text; *c != '\0'; ++c) {
		if (*c == '"' || *c == '\\')
			fprintf(out, "\\%c", *c);
		else if (*c < 0x20 || *c == '<') // '<': no "</script>" can close a page's script
			fprintf(out, "\\u%04x", *c);
		else
			fputc(*c, out);
	}
	fputc('"', out);
}

// RFC 4648 base64 of a file, streamed.
static plume_status write_base64(FILE *out, const char *path, plume_error *err)
{
	static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	FILE *in = fopen(path, "rb");
	if (in == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: %s", path, strerror(errno));
	unsigned char block[3 * 16384];
	char text[4 * 16384];
	size_t n;
	while ((n = fread(block, 1, sizeof block, in)) > 0) {
		size_t k = 0;
		for (size_t i = 0; i < n; i += 3) {
			unsigned v = (unsigned)block[i] << 16;
			if (i + 1 < n)
				v |= (unsigned)block[i + 1] << 8;
			if (i + 2 < n)
				v |= block[i + 2];
			text[k++] = alphabet[(v >> 18) & 63];
			text[k++] = alphabet[(v >> 12) & 63];
			text[k++] = i + 1 < n ? alphabet[(v >> 6) & 63] : '=';
			text[k++] = i + 2 < n ? alphabet[v & 63] : '=';
		}
		fwrite(text, 1, k, out);
		if (n < sizeof block)
			break; // a short read ends the file (or is an error, checked below)
	}
	bool ok = !ferror(in);
	fclose(in);
	return ok ? PLUME_OK : plume_error_set(err, PLUME_ERROR_IO, "%s: read error", path);
}

static plume_status write_models(const char *path, const view_file *files, int count, bool embed, plume_error *err)
{
	FILE *out = fopen(path, "w");
	if (out == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: %s", path, strerror(errno));
	fputs("// Written by `plume view`: the .glb files the page shows.\nwindow.PLUME_MODELS = [\n", out);
	plume_status status = PLUME_OK;
	for (int i = 0; i < count && status == PLUME_OK; ++i) {
		fputs("{\"name\": ", out);
		write_js_string(out, files[i].name);
		if (embed) {
			fputs(", \"data\": \"", out);
			status = write_base64(out, files[i].path, err);
			fputs("\"},\n", out);
		} else {
			fprintf(out, ", \"url\": \"/glb/%d.glb\"},\n", i);
		}
	}
	fputs("];\n", out);
	bool ok = fclose(out) == 0;
	if (status == PLUME_OK && !ok)
		status = plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	return status;
}

// ---------------------------------------------------------------------------
// --serve: a static server for the page and the listed files, bound to
// 127.0.0.1 only, a thread per connection (Chromium opens idle spare
// connections that would otherwise hold the queue up). Paths are looked up in
// a fixed table, never on disk, so nothing else can be read through it.

static volatile sig_atomic_t serving = 1;

static void stop_serving(int signal_number)
{
	(void)signal_number;
	serving = 0;
}

static void send_all(int fd, const char *data, size_t size)
{
	while (size > 0) {
		ssize_t n = send(fd, data, size, MSG_NOSIGNAL);
		if (n <= 0)
			return;
		data += n;
		size -= (size_t)n;
	}
}

static void send_status(int fd, const char *status)
{
	char head[256];
	int n = snprintf(head, sizeof head,
	                 "HTTP/1.1 %s\r\nContent-Type: text/plain\r\nContent-Length: %zu\r\nConnection: close\r\n\r\n%s",
	                 status, strlen(status), status);
	send_all(fd, head, (size_t)n);
}

static void send_file(int fd, const char *path, const char *type, bool head_only)
{
	FILE *in = fopen(path, "rb");
	struct stat info;
	if (in == NULL || fstat(fileno(in), &info) != 0) {
		if (in != NULL)
			fclose(in);
		send_status(fd, "404 Not Found");
		return;
	}
	char head[512];
	int n = snprintf(head, sizeof head,
	                 "HTTP/1.1 200 OK\r\nContent-Type: %s\r\nContent-Length: %lld\r\nCache-Control: no-store\r\n"
	                 "Connection: close\r\n\r\n",
	                 type, (long long)info.st_size);
	send_all(fd, head, (size_t)n);
	char buffer[1 << 16];
	size_t k;
	while (!head_only && (k = fread(buffer, 1, sizeof buffer, in)) > 0)
		send_all(fd, buffer, k);
	fclose(in);
}

static void serve_request(int fd, const char *page_dir, const view_file *files, int count)
{
	char request[4096];
	size_t used = 0;
	// Read up to the end of the header (the request has no body).
	while (used + 1 < sizeof request) {
		ssize_t n = recv(fd, request + used, sizeof request - 1 - used, 0);
		if (n <= 0)
			break;
		used += (size_t)n;
		request[used] = '\0';
		if (strstr(request, "\r\n\r\n") != NULL)
			break;
	}
	request[used] = '\0';
	char method[8], target[1024];
	if (sscanf(request, "%7s %1023s", method, target) != 2) {
		send_status(fd, "400 Bad Request");
		return;
	}
	bool head_only = strcmp(method, "HEAD") == 0;
	if (!head_only && strcmp(method, "GET") != 0) {
		send_status(fd, "405 Method Not Allowed");
		return;
	}
	char *query = strchr(target, '?');
	if (query != NULL)
		*query = '\0';
	static const struct {
		const char *url, *file, *type;
	} page[] = {
	    {"/", "index.html", "text/html; charset=utf-8"},
	    {"/index.html", "index.html", "text/html; charset=utf-8"},
	    {"/models.js", "models.js", "text/javascript; charset=utf-8"},
	    {"/plume-viewer.js", "plume-viewer.js", "text/javascript; charset=utf-8"},
	    {"/LICENSE.three.txt", "LICENSE.three.txt", "text/plain; charset=utf-8"},
	};
	for (size_t i = 0; i < sizeof page / sizeof page[0]; ++i) {
		if (strcmp(target, page[i].url) == 0) {
			char path[PATH_MAX + 64];
			snprintf(path, sizeof path, "%s/%s", page_dir, page[i].file);
			send_file(fd, path, page[i].type, head_only);
			return;
		}
	}
	int index;
	char tail;
	if (sscanf(target, "/glb/%d.gl%c", &index, &tail) == 2 && tail == 'b' && index >= 0 && index < count) {
		char expected[64];
		snprintf(expected, sizeof expected, "/glb/%d.glb", index);
		if (strcmp(target, expected) == 0) {
			send_file(fd, files[index].path, "model/gltf-binary", head_only);
			return;
		}
	}
	send_status(fd, "404 Not Found");
}

typedef struct serve_job {
	int fd;
	const char *page_dir;
	const view_file *files;
	int count;
} serve_job;

static void *serve_thread(void *argument)
{
	serve_job *job = argument;
	serve_request(job->fd, job->page_dir, job->files, job->count);
	close(job->fd);
	free(job);
	return NULL;
}

static int serve(int port, const char *page_dir, const view_file *files, int count)
{
	int server = socket(AF_INET, SOCK_STREAM, 0);
	if (server < 0) {
		fprintf(stderr, "plume: view: socket: %s\n", strerror(errno));
		return CLI_EXIT_IO;
	}
	int yes = 1;
	setsockopt(server, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
	struct sockaddr_in address;
	memset(&address, 0, sizeof address);
	address.sin_family = AF_INET;
	address.sin_port = htons((uint16_t)port);
	address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	if (bind(server, (struct sockaddr *)&address, sizeof address) != 0 || listen(server, 16) != 0) {
		fprintf(stderr, "plume: view: cannot listen on 127.0.0.1:%d: %s\n", port, strerror(errno));
		close(server);
		return CLI_EXIT_IO;
	}
	struct sigaction action;
	memset(&action, 0, sizeof action);
	action.sa_handler = stop_serving; // no SA_RESTART: accept() returns on Ctrl-C
	sigaction(SIGINT, &action, NULL);
	sigaction(SIGTERM, &action, NULL);
	printf("Serving http://127.0.0.1:%d/ (this machine only); Ctrl-C stops.\n", port);
	fflush(stdout);
	while (serving) {
		int client = accept(server, NULL, NULL);
		if (client < 0)
			continue;
		struct timeval timeout = {10, 0};
		setsockopt(client, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
		setsockopt(client, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
		serve_job *job = malloc(sizeof *job);
		pthread_t thread;
		if (job == NULL) {
			close(client);
			continue;
		}
		*job = (serve_job){client, page_dir, files, count};
		// Workers leave SIGINT and SIGTERM to this thread, whose accept() they end.
		sigset_t all, previous;
		sigfillset(&all);
		pthread_sigmask(SIG_SETMASK, &all, &previous);
		if (pthread_create(&thread, NULL, serve_thread, job) == 0)
			pthread_detach(thread);
		else
			serve_thread(job);
		pthread_sigmask(SIG_SETMASK, &previous, NULL);
	}
	close(server);
	return CLI_EXIT_OK;
}

// ---------------------------------------------------------------------------

int cli_view(int argc, char **argv)
{
	static const struct option options[] = {
	    {"output", required_argument, NULL, 'o'},
	    {"serve", required_argument, NULL, 'S'},
	    {"viewer", required_argument, NULL, 'V'},
	    {"help", no_argument, NULL, 'h'},
	    {NULL, 0, NULL, 0},
	};
	const char *output_dir = NULL, *viewer_option = NULL;
	int port = 0;
	optind = 1;
	opterr = 0;
	int option;
	while ((option = getopt_long(argc, argv, ":o:h", options, NULL)) != -1) {
		switch (option) {
		case 'o': output_dir = optarg; break;
		case 'V': viewer_option = optarg; break;
		case 'S': {
			char *end;
			long value = strtol(optarg, &end, 10);
			if (end == optarg || *end != '\0' || value < 1 || value > 65535)
				return cli_usage_error("view", "--serve '%s' must be a port number in [1, 65535]", optarg);
			port = (int)value;
			break;
		}
		case 'h': cli_help_view(); return CLI_EXIT_OK;
		case ':': return cli_usage_error("view", "option '%s' needs a value", argv[optind - 1]);
		default: return cli_usage_error("view", "unknown option '%s'", argv[optind - 1]);
		}
	}
	if (optind >= argc)
		return cli_usage_error("view", "missing INPUT (a .glb file or a folder of them)");
	if (optind + 1 < argc)
		return cli_usage_error("view", "unexpected argument '%s'", argv[optind + 1]);
	const char *input = argv[optind];

	plume_error err = {0};
	static view_file files[VIEW_MAX_FILES];
	int count = 0;
	char default_dir[PATH_MAX], viewer_dir[PATH_MAX];
	if (find_inputs(input, files, &count, default_dir, sizeof default_dir, &err) != PLUME_OK ||
	    find_viewer(viewer_option, viewer_dir, sizeof viewer_dir, &err) != PLUME_OK)
		return cli_fail(&err);
	bool embed = port == 0;
	for (int i = 0; embed && i < count; ++i) {
		if (files[i].size > VIEW_EMBED_LIMIT) {
			fprintf(stderr,
			        "plume: view: %s: %.0f MB is too large to embed in a page (at most %lld MB); use --serve PORT\n",
			        files[i].path, (double)files[i].size / (1 << 20), VIEW_EMBED_LIMIT >> 20);
			return CLI_EXIT_INPUT;
		}
	}
	if (output_dir == NULL)
		output_dir = default_dir;

	cli_output output;
	if (cli_output_begin(&output, output_dir, &err) != PLUME_OK)
		return cli_fail(&err);
	char path[4352], from[PATH_MAX + 64];
	for (size_t i = 0; i < sizeof viewer_assets / sizeof viewer_assets[0] && err.status == PLUME_OK; ++i) {
		snprintf(from, sizeof from, "%s/%s", viewer_dir, viewer_assets[i]);
		copy_file(from, cli_output_path(&output, viewer_assets[i], path, sizeof path), &err);
	}
	if (err.status == PLUME_OK)
		write_models(cli_output_path(&output, "models.js", path, sizeof path), files, count, embed, &err);
	if (err.status != PLUME_OK || cli_output_commit(&output, &err) != PLUME_OK) {
		cli_output_abort(&output, &err);
		return cli_fail(&err);
	}

	char absolute[PATH_MAX];
	if (realpath(output.dir, absolute) == NULL)
		snprintf(absolute, sizeof absolute, "%s", output.dir);
	printf("Wrote %s/index.html: %d file%s (", output.dir, count, count == 1 ? "" : "s");
	for (int i = 0; i < count; ++i)
		printf("%s%s", i > 0 ? ", " : "", files[i].name);
	if (!embed) {
		printf(") served, not embedded.\n");
		return serve(port, absolute, files, count);
	}
	printf(") embedded.\nOpen file://%s/index.html in a browser (e.g. chromium, firefox).\n", absolute);
	return CLI_EXIT_OK;
}
