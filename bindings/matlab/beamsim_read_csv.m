%BEAMSIM_READ_CSV One CSV table of beamsim into a struct of columns (a MEX function).
%   T = BEAMSIM_READ_CSV(FILE) reads one table that beamsim wrote: one field
%   per column, named by the header; a column whose every field is a
%   number, empty or nan is a double column (empty and nan are NaN), any
%   other a cell column of text. The file's numbers as they are (groups and
%   trials from 0); BEAMSIM_LOAD, which reads whole output directories with
%   it, adds 1 to the group and trial columns.
%
%   See also BEAMSIM_LOAD.
