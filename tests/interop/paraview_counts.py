# Runs inside ParaView (pvbatch3.11 THIS JOBS.json RESULTS.json): opens each
# job's file with ParaView's own reader and reports points, cells and time
# steps; interop.py compares them with what plume wrote.
import json
import sys

from paraview import simple


def counts(path):
    reader = simple.OpenDataFile(path)
    if reader is None:
        return {"error": "ParaView has no reader for " + path}
    times = list(getattr(reader, "TimestepValues", None) or [])
    first = simple.servermanager.Fetch(reader)
    result = {
        "reader": reader.GetXMLName(),
        "timesteps": len(times),
        "points": first.GetNumberOfPoints(),
        "cells": first.GetNumberOfCells(),
    }
    if first.IsA("vtkPolyData"):
        result["lines"] = first.GetNumberOfLines()
        result["line_segments"] = sum(
            first.GetCell(i).GetNumberOfPoints() - 1 for i in range(first.GetNumberOfCells()) if first.GetCellType(i) in (3, 4)
        )
        result["polys"] = first.GetNumberOfPolys()
    data = first.GetCellData()
    result["cell_arrays"] = sorted(data.GetArrayName(i) for i in range(data.GetNumberOfArrays()))
    data = first.GetPointData()
    result["point_arrays"] = sorted(data.GetArrayName(i) for i in range(data.GetNumberOfArrays()))
    if len(times) > 1:
        # The last step too: a collection whose later files are broken fails here.
        reader.UpdatePipeline(times[-1])
        last = simple.servermanager.Fetch(reader)
        result["last_points"] = last.GetNumberOfPoints()
        result["last_cells"] = last.GetNumberOfCells()
    simple.Delete(reader)
    return result


jobs = json.load(open(sys.argv[1]))
results = []
for job in jobs:
    try:
        result = counts(job["path"])
    except Exception as error:
        result = {"error": "%s: %s" % (type(error).__name__, error)}
    results.append(dict(job, paraview=result))
json.dump(results, open(sys.argv[2], "w"), indent=1)
