// plume simulate --fields: VTK XML files for ParaView. One unstructured grid
// (.vtu, ASCII) per frame with the shell's triangles, and one collection (.pvd)
// that lists them with their times.
//
// Per face (CellData): Green strain and second Piola-Kirchhoff stress in the barb
// frame (v along the barb at the face's barb angle, w across: components vv, ww,
// vw as tensor components), the barb angle (radians from the reference +x axis),
// the material index, and the membrane, compression and bending energy densities
// (J/m^2 of reference area), from plume_sim_face_fields. Per vertex (PointData):
// velocity (m/s) and the index of the handle that holds it (-1: free).
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"

/// Rotates a symmetric tensor (xx, yy, xy) into the frame v = (c, s), w = (-s, c).
static void to_barb_frame(const double t[3], double angle, double out[3])
{
	double c = cos(angle), s = sin(angle);
	out[0] = c * c * t[0] + s * s * t[1] + 2 * s * c * t[2];
	out[1] = s * s * t[0] + c * c * t[1] - 2 * s * c * t[2];
	out[2] = -s * c * t[0] + s * c * t[1] + (c * c - s * s) * t[2];
}

static void begin_array(FILE *s, const char *type, const char *name, int components)
{
	fprintf(s, "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"ascii\">\n", type, name,
	        components);
}

static void end_array(FILE *s) { fputs("\n        </DataArray>\n", s); }

plume_status cli_fields_write_frame(cli_output *output, const plume_scene *scene, const plume_sim *sim, int frame,
                                    plume_error *err)
{
	const plume_mesh *mesh = scene->mesh;
	int n = mesh->vertex_count, faces = mesh->face_count;
	plume_sim_face_field *fields = malloc((size_t)(faces > 0 ? faces : 1) * sizeof *fields);
	int *handle = malloc((size_t)(n > 0 ? n : 1) * sizeof *handle);
	if (fields == NULL || handle == NULL) {
		free(fields);
		free(handle);
		return plume_error_set(err, PLUME_ERROR_MEMORY, "fields: out of memory");
	}
	plume_status status = plume_sim_face_fields(sim, fields, err);
	for (int i = 0; i < n; ++i)
		handle[i] = -1;
	for (int h = 0; h < scene->handle_count; ++h)
		for (int g = 0; g < mesh->group_count; ++g)
			if (strcmp(mesh->groups[g].name, scene->handles[h].group) == 0)
				for (int k = 0; k < mesh->groups[g].count; ++k)
					handle[mesh->groups[g].vertices[k]] = h;
	char name[64], path[4352];
	snprintf(name, sizeof name, "fields/%04d.vtu", frame);
	cli_output_path(output, name, path, sizeof path);
	FILE *s = status == PLUME_OK ? fopen(path, "wb") : NULL;
	if (status == PLUME_OK && s == NULL)
		status = plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	if (s != NULL) {
		const plume_vec3 *x = plume_sim_positions(sim), *v = plume_sim_velocities(sim);
		fprintf(s, "<?xml version=\"1.0\"?>\n"
		           "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
		           "header_type=\"UInt64\">\n"
		           "  <UnstructuredGrid>\n");
		fprintf(s, "    <Piece NumberOfPoints=\"%d\" NumberOfCells=\"%d\">\n      <Points>\n", n, faces);
		begin_array(s, "Float64", "Points", 3);
		for (int i = 0; i < n; ++i)
			fprintf(s, "%s%.17g %.17g %.17g", i > 0 ? " " : "", x[i].x, x[i].y, x[i].z);
		end_array(s);
		fputs("      </Points>\n      <Cells>\n", s);
		begin_array(s, "Int64", "connectivity", 1);
		for (int k = 0; k < 3 * faces; ++k)
			fprintf(s, "%s%d", k > 0 ? " " : "", mesh->faces[k]);
		end_array(s);
		begin_array(s, "Int64", "offsets", 1);
		for (int f = 0; f < faces; ++f)
			fprintf(s, "%s%d", f > 0 ? " " : "", 3 * (f + 1));
		end_array(s);
		begin_array(s, "UInt8", "types", 1);
		for (int f = 0; f < faces; ++f)
			fputs(f > 0 ? " 5" : "5", s); // VTK_TRIANGLE
		end_array(s);
		fputs("      </Cells>\n      <PointData Vectors=\"velocity\">\n", s);
		begin_array(s, "Float64", "velocity", 3);
		for (int i = 0; i < n; ++i)
			fprintf(s, "%s%.17g %.17g %.17g", i > 0 ? " " : "", v[i].x, v[i].y, v[i].z);
		end_array(s);
		begin_array(s, "Int32", "handle", 1);
		for (int i = 0; i < n; ++i)
			fprintf(s, "%s%d", i > 0 ? " " : "", handle[i]);
		end_array(s);
		fputs("      </PointData>\n      <CellData>\n", s);
		for (int which = 0; which < 2; ++which) {
			begin_array(s, "Float64", which == 0 ? "green_strain_barb" : "pk2_stress_barb", 3);
			for (int f = 0; f < faces; ++f) {
				double t[3];
				to_barb_frame(which == 0 ? fields[f].strain : fields[f].stress, mesh->barb_angle[f], t);
				fprintf(s, "%s%.17g %.17g %.17g", f > 0 ? " " : "", t[0], t[1], t[2]);
			}
			end_array(s);
		}
		begin_array(s, "Float64", "barb_angle", 1);
		for (int f = 0; f < faces; ++f)
			fprintf(s, "%s%.17g", f > 0 ? " " : "", mesh->barb_angle[f]);
		end_array(s);
		begin_array(s, "Int32", "material", 1);
		for (int f = 0; f < faces; ++f)
			fprintf(s, "%s%d", f > 0 ? " " : "", mesh->material[f]);
		end_array(s);
		static const char *const densities[3] = {"membrane_energy_density", "compression_energy_density",
		                                         "bending_energy_density"};
		for (int d = 0; d < 3; ++d) {
			begin_array(s, "Float64", densities[d], 1);
			for (int f = 0; f < faces; ++f) {
				double value = d == 0   ? fields[f].membrane_energy_density
				               : d == 1 ? fields[f].compression_energy_density
				                        : fields[f].bending_energy_density;
				fprintf(s, "%s%.17g", f > 0 ? " " : "", value);
			}
			end_array(s);
		}
		fputs("      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n", s);
		bool failed = ferror(s) != 0;
		if (fclose(s) != 0 || failed)
			status = plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	}
	free(fields);
	free(handle);
	return status;
}

plume_status cli_fields_write_pvd(cli_output *output, const double *times, int frames, plume_error *err)
{
	char path[4352];
	cli_output_path(output, "fields.pvd", path, sizeof path);
	FILE *s = fopen(path, "wb");
	if (s == NULL)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n", s);
	for (int k = 0; k < frames; ++k)
		fprintf(s, "    <DataSet timestep=\"%.17g\" part=\"0\" file=\"fields/%04d.vtu\"/>\n", times[k], k);
	fputs("  </Collection>\n</VTKFile>\n", s);
	bool failed = ferror(s) != 0;
	if (fclose(s) != 0 || failed)
		return plume_error_set(err, PLUME_ERROR_IO, "%s: cannot write", path);
	return PLUME_OK;
}
