"""Shared by the script tests: the drop's CSV headers and the scripts' table reader."""

HISTORY_HEAD = ("t,x,y,z,vx,vy,vz,speed,canopy_diameter,open_force,payload_phi_x,payload_phi_y,canopy_phi_x,"
                "canopy_phi_y,flight_path_angle,drag_coefficient,open_force_filtered")
SUMMARY_HEAD = "fabric,t_f,t_mo,t_p,F_p,v_terminal,cd_terminal,attitude_amplitude,descent_mode"


def table(out, header):
    """Rows after the line `header` until the next comment line, as lists of words."""
    lines = out.splitlines()
    i = lines.index(header)
    rows = []
    for line in lines[i + 1:]:
        if line.startswith("#"):
            break
        rows.append(line.split())
    return rows
